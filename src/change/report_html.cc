// changes.html: one page for the inspector. A plan of both flights with every change as a numbered marker,
// beside a table of the changes with their before and after pictures (a click on a marker selects its row and
// a click on a row its marker), then every object with the reason for its state. Pictures are files in the
// images folder, loaded as their rows come into view, or embedded when there is no folder. No network at view time.
// When the page has initialised, <body> carries data-ready="N markers" and data-ready-ms, the milliseconds it took to
// get there.
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>

#include "patrolmap/core/words.h"
#include "patrolmap/graph/export.h"
#include "report_plan.h"

namespace patrolmap::change {
namespace {

// When a patrol was flown: a date for log times that are Unix times (after 1973), else the log's own seconds.
std::string FlownAt(TimestampNs ns) {
  constexpr TimestampNs kUnixTimesFrom = 100000000LL * 1000000000LL;
  if (ns < kUnixTimesFrom) return "at " + Fixed(NsToSeconds(ns), 1) + " s of its log";
  const std::time_t seconds = static_cast<std::time_t>(ns / 1000000000LL);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M UTC", &utc);
  return text;
}

// "1 place", "3 places".
std::string Counted(long long n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

constexpr char kStyle[] = R"(
body{font-family:system-ui,sans-serif;margin:0;color:#1f2933;background:#fff}
header{padding:12px 20px;border-bottom:1px solid #e4e7eb}h1{font-size:20px;margin:0 0 4px}
.summary{margin:0;color:#52606d}
main{display:grid;grid-template-columns:minmax(360px,42%) 1fr;gap:16px;padding:12px 20px}
#plan svg{width:100%;height:auto;border:1px solid #d9dee4;display:block}
.legend{font-size:12px;color:#52606d;margin:6px 0}.legend span{margin-right:12px;display:inline-block}
#plan{position:sticky;top:0;align-self:start}
.swatch{display:inline-block;width:12px;height:12px;border-radius:6px;vertical-align:-2px;margin-right:4px}
table{border-collapse:collapse;width:100%;font-size:13px}th,td{border-bottom:1px solid #e4e7eb;padding:6px;
text-align:left;vertical-align:top}th{background:#f5f7fa;position:sticky;top:0}
#changes tr{cursor:pointer}#changes tr.selected{background:#fff7d6}
.badge{display:inline-block;min-width:22px;height:22px;border-radius:11px;color:#fff;text-align:center;
font-weight:bold;line-height:22px}
.seen{font-size:12px;color:#52606d}
figure{margin:0}figure img{display:block;border:1px solid #cbd2d9;max-width:240px;height:auto;background:#eee}
figcaption{font-size:11px;color:#52606d}.none{color:#9aa5b1;font-size:12px}
.marker{cursor:pointer}.marker.selected circle{stroke:#111;stroke-width:3}
section.more{padding:0 20px 20px}
)";

constexpr char kScript[] = R"(
const rows = new Map();
document.querySelectorAll('#changes tr[data-id]').forEach(r => rows.set(r.dataset.id, r));
const markers = new Map();
document.querySelectorAll('#plan .marker').forEach(m => markers.set(m.dataset.id, m));
function select(id, from) {
  document.querySelectorAll('.selected').forEach(e => e.classList.remove('selected'));
  const row = rows.get(id), marker = markers.get(id);
  if (row) { row.classList.add('selected'); if (from === 'plan') row.scrollIntoView({block: 'center'}); }
  if (marker) { marker.classList.add('selected'); marker.parentNode.appendChild(marker); }
}
markers.forEach((m, id) => m.addEventListener('click', () => select(id, 'plan')));
const pictures = document.querySelectorAll('img[data-src]');
const show = im => { im.src = im.dataset.src; im.removeAttribute('data-src'); };
if ('IntersectionObserver' in window) {
  const near = new IntersectionObserver(seen => seen.forEach(e => {
    if (e.isIntersecting) { show(e.target); near.unobserve(e.target); }
  }), {rootMargin: '800px'});
  pictures.forEach(im => near.observe(im));
} else {
  pictures.forEach(show);
}
rows.forEach((r, id) => r.addEventListener('click', () => select(id, 'table')));
document.body.dataset.ready = markers.size + ' markers';
document.body.dataset.readyMs = Math.round(performance.now());  // since navigation started
)";

std::string Where(const ChangeItem& item, const std::optional<GeoReference>& geo) {
  if (!item.position && item.bearing) {
    const Eigen::Vector3d& o = item.bearing->origin;
    const double heading = std::atan2(item.bearing->direction.x(), item.bearing->direction.y()) * 180.0 / M_PI;
    return "<span class='none'>on a bearing, no depth:</span> within " + Fixed(item.bearing_range_m, 0) +
           " m of the camera at " + Fixed(o.x(), 1) + ", " + Fixed(o.y(), 1) + ", " + Fixed(o.z(), 1) + " m, heading " +
           Fixed(std::fmod(heading + 360.0, 360.0), 0) + "&#176; (from +y, clockwise)";
  }
  if (!item.position) return "<span class='none'>no pose</span>";
  const Eigen::Vector3d& p = *item.position;
  std::string where = Fixed(p.x(), 1) + ", " + Fixed(p.y(), 1) + ", " + Fixed(p.z(), 1) + " m";
  if (geo) {
    const Eigen::Vector2d ll = geo->LatitudeLongitude(p);
    where += "<br>" + Fixed(ll.x(), 6) + "&#176;, " + Fixed(ll.y(), 6) + "&#176;";
  }
  if (item.from) where += "<br>moved " + Fixed((p - *item.from).head<2>().norm(), 1) + " m";
  return where;
}

std::string Figure(const ChangeItem& item, bool before, const std::string& images) {
  const ChangeView& view = before ? item.before : item.after;
  const char* word = before ? "before" : "after";
  if (view.image.empty()) {
    return std::string("<span class='none'>") + word + ": no kept frame of " + graph::EscapeXml(view.flight) +
           " shows it</span>";
  }
  // A file is loaded when its row comes near the view (data-src; the script), so a report of hundreds of
  // changes opens at once: Chromium loads file:// images eagerly even with loading='lazy'.
  const std::string source = images.empty()
                                 ? "src='" + graph::PngDataUri(view.image) + "'"
                                 : "data-src='" + graph::EscapeXml(images + "/" + ViewFileName(item, before)) + "'";
  std::ostringstream out;
  out << "<figure><img loading='lazy' alt='" << word << "' " << source << " width='" << view.image.cols << "' height='"
      << view.image.rows << "'><figcaption>" << word << ": " << graph::EscapeXml(view.flight) << ", "
      << Fixed(NsToSeconds(view.timestamp_ns), 1) << " s, frame " << view.frame_index << "</figcaption></figure>";
  return out.str();
}

// A detected object's site object: the id it keeps across the map's patrols (`patrolmap history`).
std::string SiteObject(const ChangeItem& item) {
  if (item.site_object < 0) return std::string();
  const std::string id = std::to_string(item.site_object);
  return " \u00b7 <a href='#site-" + id + "'>site object " + id + "</a>";
}

// The channels that saw the change, in one line: each with how many findings it gave and the best one's confidence
// (the findings themselves are in the row's tooltip and in changes.json); and whether its place was out of 3D reach.
std::string SeenBy(const ChangeItem& item) {
  const std::string unranged = item.compared_in_3d == false ? "<br><span class='seen'>not compared in 3D: no depth of "
                                                              "one patrol or the other reached it</span>"
                                                            : "";
  if (item.evidence.empty()) return unranged;
  std::string text = "<br><span class='seen'>seen by " + graph::EscapeXml(item.channels.front());
  for (std::size_t c = 1; c < item.channels.size(); ++c) {
    int count = 0;
    double best = 0.0;
    for (const ChangeEvidence& e : item.evidence) {
      if (e.channel == item.channels[c]) ++count, best = std::max(best, e.confidence);
    }
    text += ", " + graph::EscapeXml(item.channels[c]) + (count > 1 ? " &#215;" + std::to_string(count) : "") + " (" +
            Fixed(best, 2) + ")";
  }
  return text + "</span>" + unranged;
}

// The row's tooltip: its id and every finding fused into it.
std::string RowTitle(const ChangeItem& item) {
  std::string title = item.id;
  for (const ChangeEvidence& e : item.evidence) {
    title += "\n" + e.id + ": " + e.kind + " " + e.state + ", " + e.label + " (" + Fixed(e.confidence, 2) + ")";
  }
  return graph::EscapeXml(title);
}

void ChangeRows(const std::vector<ChangeItem>& items, const std::optional<GeoReference>& geo, const std::string& images,
                std::ostringstream* html) {
  *html << "<p class='note'>Confidence, from 0 to 1: how sure each channel is (detections: the detector's mean score; "
           "geometry: the changed voxels' evidence; appearance: the structure change, the depth that marked it and "
           "the views that agree). A change several channels saw counts them as independent witnesses: 1 minus the "
           "product of (1 - each one's).</p>\n";
  *html << "<table id='changes'><tr><th>#</th><th>change</th><th>confidence</th><th>where</th><th>before</th>"
           "<th>after</th></tr>\n";
  for (const ChangeItem& item : items) {
    *html << "<tr id='row-" << graph::EscapeXml(item.id) << "' data-id='" << graph::EscapeXml(item.id) << "' title='"
          << RowTitle(item) << "'><td><span class='badge' style='background:" << ChangeColour(item) << "'>"
          << item.number << "</span></td><td><b>" << graph::EscapeXml(item.kind) << " " << graph::EscapeXml(item.state)
          << "</b>: " << graph::EscapeXml(item.label) << SiteObject(item) << SeenBy(item) << "</td><td>"
          << Fixed(item.confidence, 2) << "</td><td>" << Where(item, geo) << "</td><td>" << Figure(item, true, images)
          << "</td><td>" << Figure(item, false, images) << "</td></tr>\n";
  }
  *html << "</table>\n";
}

// Why an object has its state, in an inspector's words.
// Why a class-agnostic object (a cluster of changed voxels) has its state.
std::string GeometryReason(const ObjectChange& o) {
  const auto voxels = [](const Eigen::AlignedBox3d& box) {
    return Fixed(box.sizes().x(), 1) + " x " + Fixed(box.sizes().y(), 1) + " m";
  };
  switch (o.state) {
    case ObjectState::kNew: return "space free before is occupied now, over " + voxels(o.box_after) + " (no detector)";
    case ObjectState::kRemoved:
      return "space occupied before is seen free now, over " + voxels(o.box_before) + " (no detector)";
    case ObjectState::kMoved:
      return "space freed and space filled alike in shape, " + Fixed((*o.after - *o.before).head<2>().norm(), 1) +
             " m apart, turned " + Fixed(std::atan2(o.rotation(1, 0), o.rotation(0, 0)) * 180.0 / M_PI, 0) +
             "&#176; (no detector)";
    default: return "";
  }
}

std::string Reason(const ObjectChange& o) {
  if (o.class_agnostic) return GeometryReason(o);
  switch (o.state) {
    case ObjectState::kPersistent: return "seen in both patrols at the same place";
    case ObjectState::kNew: return "not in the prior patrol's map there";
    case ObjectState::kMoved:
      return "moved " + Fixed((*o.after - *o.before).head<2>().norm(), 1) + " m, turned " +
             Fixed(std::atan2(o.rotation(1, 0), o.rotation(0, 0)) * 180.0 / M_PI, 0) + "&#176;";
    case ObjectState::kRemoved:
      return Counted(o.covering_views, "view", "views") + " of this patrol covered it (about " +
             Fixed(o.expected_detections, 1) + " detections expected); none found it";
    case ObjectState::kUnobserved:
      return "this patrol did not look at it closely enough to tell (" + Counted(o.covering_views, "view", "views") +
             ", about " + Fixed(o.expected_detections, 1) + " detections expected)";
  }
  return "";
}

void ObjectTable(const ChangeReport& report, std::ostringstream* html) {
  const auto position = [](const std::optional<Eigen::Vector3d>& p) {
    return p ? Fixed(p->x(), 1) + ", " + Fixed(p->y(), 1) + ", " + Fixed(p->z(), 1) : std::string("&ndash;");
  };
  *html << "<section class='more'><h2>All objects</h2><table><tr><th>state</th><th>label</th><th>confidence</th>"
           "<th>before [m]</th><th>after [m]</th><th>why</th></tr>\n";
  for (const ObjectChange& o : report.objects) {
    *html << "<tr><td>" << ToString(o.state) << "</td><td>" << graph::EscapeXml(o.label) << "</td><td>"
          << Fixed(o.confidence, 2) << "</td><td>" << position(o.before) << "</td><td>" << position(o.after)
          << "</td><td>" << Reason(o) << "</td></tr>\n";
  }
  *html << "</table></section>\n";
}

// Each site object the report's object changes concern, with its history over the map's patrols; the rows link here.
void SiteObjectTimelines(const ChangeReport& report, std::ostringstream* html) {
  if (report.site_objects.empty()) return;
  const auto where = [](const std::optional<Eigen::Vector3d>& p) {
    return p ? "(" + Fixed(p->x(), 1) + ", " + Fixed(p->y(), 1) + ")" : std::string();
  };
  *html << "<section class='more'><h2>Site objects</h2><p>Each object keeps its id across the map's patrols "
           "(<code>patrolmap history</code>).</p>\n";
  for (const SiteObjectHistory& h : report.site_objects) {
    *html << "<h3 id='site-" << h.id << "'>site object " << h.id << ": " << graph::EscapeXml(h.label) << "</h3><ol>";
    for (const SiteEvent& e : h.events) {
      *html << "<li>patrol " << e.patrol << " (" << graph::EscapeXml(e.flight) << "): " << e.what;
      if (e.from && e.to)
        *html << " from " << where(e.from) << " to " << where(e.to);
      else
        *html << " at " << where(e.to ? e.to : e.from);
      *html << "</li>";
    }
    *html << "</ol>\n";
  }
  *html << "</section>\n";
}

const char* DepthWords(const std::string& source) {
  if (source == kDepthFromImages) return "depth images";
  if (source == kDepthFromStereo) return "stereo matching";
  if (source == kDepthFromFlight) return "motion stereo between the flight's frames";
  return "unrecorded";
}

const char* PoseWords(const std::string& source) {
  if (source == kPosesFromStateEstimate) return "the log's state estimate";
  if (source == kPosesFromTopic) return "the bag's pose topic";
  if (source == kPosesFromFile) return "a pose file";
  if (source == kPosesFromGps) return "GPS and the IMU's attitude";
  return "unrecorded";
}

void Summary(const ChangeReport& report, const std::vector<ChangeItem>& items, std::ostringstream* html) {
  *html << "<p class='summary'>" << Counted(static_cast<long long>(items.size()), "change", "changes") << ". "
        << Counted(static_cast<long long>(report.places.size()), "place", "places") << " seen by both patrols, "
        << report.ChangedPlaces() << " changed in appearance.";
  if (report.route.compared) {
    *html << " Along the route: " << report.route.pairs.size() << " of "
          << Counted(report.route.current_frames, "frame", "frames") << " compared ("
          << Fixed(100.0 * report.route.ComparedShare(), 0) << " %), "
          << Counted(static_cast<long long>(report.route.changes.size()), "appearance change", "appearance changes")
          << ".";
    if (report.route.current_depth_frames > 0) {
      *html << " Depth from the route's own frames (motion stereo) for " << report.route.current_depth_frames << " of "
            << Counted(report.route.current_frames, "frame", "frames") << ".";
    }
  }
  if (report.objects_compared) {
    *html << " Objects: " << report.ObjectsIn(ObjectState::kNew) << " new, " << report.ObjectsIn(ObjectState::kRemoved)
          << " removed, " << report.ObjectsIn(ObjectState::kMoved) << " moved, "
          << report.ObjectsIn(ObjectState::kPersistent) << " persistent, " << report.ObjectsIn(ObjectState::kUnobserved)
          << " unobserved.";
  }
  if (report.geometry_compared) {
    *html << " Geometry: "
          << Counted(static_cast<long long>(report.geometry.regions.size()), "changed region", "changed regions")
          << " (depth from " << DepthWords(report.geometry.depth_prior) << " before, "
          << DepthWords(report.geometry.depth_current) << " now).";
    if (report.geometry.poses_disagree) {
      *html << " No geometry or object change is reported: the two patrols' surfaces differ in "
            << static_cast<int>(std::lround(100.0 * report.geometry.DifferingShare()))
            << " % of the voxels both observed, so their camera poses disagree (GPS without RTK, or another "
               "world frame).";
    }
    if (report.grid_sources.size() > 1) {
      *html << " Where " << graph::EscapeXml(report.prior_flight)
            << " did not observe, the geometry was compared with the latest patrol that did:";
      for (std::size_t i = 1; i < report.grid_sources.size(); ++i) {
        const GridSource& s = report.grid_sources[i];
        *html << (i > 1 ? "," : "") << " " << graph::EscapeXml(s.flight) << " (" << s.voxels << " voxels, flown "
              << FlownAt(s.flown_ns) << ")";
      }
      *html << ".";
    }
    if (report.geometry.evicted_prior > 0 || report.geometry.evicted_current > 0) {
      *html << " The evidence grids reached their memory budget (change.grid.memory_mb) and dropped "
            << report.geometry.evicted_prior << " and " << report.geometry.evicted_current
            << " voxels: no geometry change can be found where they were.";
    }
  }
  if (!report.pose_prior.empty() || !report.pose_current.empty()) {
    *html << " Camera poses from " << PoseWords(report.pose_prior) << " before, " << PoseWords(report.pose_current)
          << " now.";
  }
  *html << "</p>\n";
}

void Legend(const std::optional<GeoReference>& geo, std::ostringstream* html) {
  *html << "<div class='legend'>";
  for (const auto& [colour, words] :
       {std::pair{"#16a34a", "new object"}, std::pair{"#dc2626", "removed object"},
        std::pair{"#ea580c", "moved object"}, std::pair{"#7c3aed", "geometry"}, std::pair{"#0891b2", "appearance"}}) {
    *html << "<span><i class='swatch' style='background:" << colour << "'></i>" << words << "</span>";
  }
  *html << "<span>&#9472; this flight</span><span>- - - prior flight</span><span style='color:#2563eb'>&#9671; "
           "place both saw</span>";
  if (geo) {
    *html << "<span>grid: latitude and longitude (GPS fit of " << geo->fixes << " fixes, " << Fixed(geo->rms_m, 1)
          << " m rms)</span>";
  }
  *html << "</div>\n";
}

}  // namespace

std::string ToHtml(const ChangeReport& report, const graph::TopoMap& map, const std::vector<ChangeItem>& items,
                   const std::optional<GeoReference>& geo, const std::string& images) {
  std::ostringstream html;
  const std::string title =
      "Changes from " + graph::EscapeXml(report.prior_flight) + " to " + graph::EscapeXml(report.current_flight);
  html << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><meta name='viewport' "
          "content='width=device-width'><title>"
       << title << "</title>\n<style>" << kStyle << "</style></head>\n<body>\n<header><h1>" << title << "</h1>\n";
  Summary(report, items, &html);
  html << "</header>\n<main>\n<section id='plan'>";
  const std::string plan = PlanSvg(report, map, items, geo);
  if (plan.empty()) {
    html << "<p class='none'>No plan: the logs have no poses.</p>";
  } else {
    html << plan;
    Legend(geo, &html);
  }
  html << "</section>\n<section id='list'>";
  if (items.empty())
    html << "<p>Nothing changed between the two patrols.</p>";
  else
    ChangeRows(items, geo, images, &html);
  html << "</section>\n</main>\n";
  if (report.objects_compared) ObjectTable(report, &html);
  SiteObjectTimelines(report, &html);
  html << "<script>" << kScript << "</script>\n</body></html>\n";
  return html.str();
}

}  // namespace patrolmap::change
