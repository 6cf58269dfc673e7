// The tables of eval::ScoreRun's result.
#include <algorithm>
#include <string>

#include <fmt/printf.h>

#include "patrolmap/eval/run_score.h"

namespace patrolmap::eval {
namespace {

// A score right-aligned in `width` columns, or an em dash when it has no cases (a recall with nothing to find,
// a precision with nothing reported).
std::string Score(double value, bool defined, int width) {
  char text[32];
  if (defined) {
    std::snprintf(text, sizeof(text), "%*.2f", width, value);
    return text;
  }
  return std::string(static_cast<std::size_t>(std::max(0, width - 1)), ' ') + "\u2014";
}

void PrintCounts(const char* name, const nlohmann::json& c, std::string* out) {
  const int tp = c["true_positives"].get<int>(), fp = c["false_positives"].get<int>();
  const int fn = c["false_negatives"].get<int>();
  *out += fmt::sprintf("%-18s %5d %6d %7d %s %s %s\n", name, tp, fp, fn,
                       Score(c["precision"].get<double>(), tp + fp > 0, 10).c_str(),
                       Score(c["recall"].get<double>(), tp + fn > 0, 7).c_str(),
                       Score(c["f1"].get<double>(), tp + fp > 0 && tp + fn > 0, 6).c_str());
}

void PrintChangeTable(const nlohmann::json& c, std::string* out) {
  *out += fmt::sprintf("changes %s -> %s: %d places compared, %d with appearance changes\n",
                       c["prior_flight"].get<std::string>().c_str(), c["current_flight"].get<std::string>().c_str(),
                       c["places_compared"].get<int>(), c["places_changed"].get<int>());
  *out += fmt::sprintf("%-18s %5s %6s %7s %10s %7s %6s\n", "", "true", "false", "missed", "precision", "recall", "F1");
  if (c.contains("objects")) {
    for (const char* state : {"new", "removed", "moved", "persistent"}) {
      PrintCounts((std::string("objects ") + state).c_str(), c["objects"][state], out);
    }
    PrintCounts("object changes", c["objects"]["changes"], out);
    if (c["objects"].contains("observable_changes"))
      PrintCounts("  observable", c["objects"]["observable_changes"], out);
  }
  if (c.contains("appearance")) {
    const nlohmann::json& a = c["appearance"];
    const double p = a["precision"].get<double>(), r = a["recall"].get<double>();
    const int regions = a["regions"].get<int>(), changes = a["changes"].get<int>();
    *out += fmt::sprintf("%-18s %5d %6d %7d %s %s %s\n", "appearance regions", a["regions_on_change"].get<int>(),
                         regions - a["regions_on_change"].get<int>(), changes - a["changes_found"].get<int>(),
                         Score(p, regions > 0, 10).c_str(), Score(r, changes > 0, 7).c_str(),
                         Score(p + r > 0 ? 2 * p * r / (p + r) : 0.0, regions > 0 && changes > 0, 6).c_str());
    *out +=
        fmt::sprintf("appearance: %d regions, %d object changes visible in the key frames of %d registered places\n",
                     regions, changes, a["places"].get<int>());
  }
  if (c.contains("route")) {
    const nlohmann::json& r = c["route"];
    const int changes = r["changes"].get<int>(), visible = r["visible"].get<int>();
    *out += fmt::sprintf(
        "route: %d of %d frames compared (%.0f %%); %d changes, %d on an object change (precision %s), "
        "%d of %d visible object changes found (recall %s)\n",
        r["pairs"].get<int>(), r["frames"].get<int>(), 100.0 * r["compared_share"].get<double>(), changes,
        r["changes_on_change"].get<int>(), Score(r["precision"].get<double>(), changes > 0, 0).c_str(),
        r["found"].get<int>(), visible, Score(r["recall"].get<double>(), visible > 0, 0).c_str());
    *out +=
        fmt::sprintf("route: of those in a prior frame (objects that left, places a moved one left): %d of %d found\n",
                     r["found_in_prior"].get<int>(), r["visible_in_prior"].get<int>());
    if (r.contains("lost_at") && !r["lost_at"].empty()) {
      std::string lost;
      for (const auto& [step, count] : r["lost_at"].items())
        lost += (lost.empty() ? "" : ", ") + step + " " + std::to_string(count.get<int>());
      *out += fmt::sprintf("route: the changes not found were lost at: %s\n", lost.c_str());
    }
  }
  if (c.contains("entries")) {
    const nlohmann::json& e = c["entries"];
    const int placed = e["entries"].get<int>() - e["bearings"].get<int>();
    *out += fmt::sprintf(
        "change list: %d entries (%d by a bearing only), %d of %d placed on a true change (precision %s); found %d of "
        "%d true changes (recall %s, F1 %s), %d of %d observable ones (recall %s, F1 %s)\n",
        e["entries"].get<int>(), e["bearings"].get<int>(), e["true_entries"].get<int>(), placed,
        Score(e["precision"].get<double>(), placed > 0, 0).c_str(), e["found"].get<int>(), e["true_changes"].get<int>(),
        Score(e["recall"].get<double>(), e["true_changes"].get<int>() > 0, 0).c_str(),
        Score(e["f1"].get<double>(), placed > 0, 0).c_str(), e["observable_found"].get<int>(),
        e["observable"].get<int>(),
        Score(e["recall_observable"].get<double>(), e["observable"].get<int>() > 0, 0).c_str(),
        Score(e["f1_observable"].get<double>(), placed > 0, 0).c_str());
  }
  if (c.contains("site_objects")) {
    const nlohmann::json& s = c["site_objects"];
    *out += fmt::sprintf(
        "site objects: over %d patrols, %d of %d true objects seen in consecutive patrols kept their id (%d changed); "
        "%d ids held more than one true object\n",
        s["patrols"].get<int>(), s["kept"].get<int>(), s["tracked"].get<int>(), s["changed"].get<int>(),
        s["merged"].get<int>());
  }
  if (c.contains("geometry")) {
    PrintCounts("voxels", c["geometry"], out);
    *out += fmt::sprintf("geometry: IoU %.2f over %lld voxels observed in both flights, %d regions\n",
                         c["geometry"]["iou"].get<double>(), c["geometry"]["observed_voxels"].get<long long>(),
                         c["geometry"]["regions"].get<int>());
    *out += fmt::sprintf(
        "geometry: %lld of the false voxels lie within %.2g m of an object that changed (a change reported "
        "too wide)\n",
        c["geometry"]["false_positives_near_change"].get<long long>(), c["geometry"]["near_change_m"].get<double>());
  }
}

void PrintKeyLocations(const nlohmann::json& k, bool spans, std::string* out) {
  *out += fmt::sprintf("key locations (paper 002 Table II), tolerance %.2f s\n", k["tolerance_s"].get<double>());
  *out += fmt::sprintf("%-20s %8s %6s %9s %5s %6s %7s %10s %7s\n", "flight", "frames", "nodes", "expected", "true",
                       "false", "missed", "precision", "recall");
  *out += fmt::sprintf("%-20s %8lld %6d %9d %5d %6d %7d %s %s\n", k["flight"].get<std::string>(),
                       k["frames"].get<long long>(), k["nodes"].get<int>(), k["expected"].get<int>(),
                       k["true_positives"].get<int>(), k["false_positives"].get<int>(), k["missed"].get<int>(),
                       Score(k["precision"].get<double>(), k["nodes"].get<int>() > 0, 10),
                       Score(k["recall"].get<double>(), k["expected"].get<int>() > 0, 7));
  if (!spans || !k.contains("spans")) return;
  const auto time = [](const nlohmann::json& t, const char* open) {
    return t.is_null() ? std::string(open) : fmt::sprintf("%7.2f", t.get<double>());
  };
  for (const nlohmann::json& span : k["spans"]) {
    *out += fmt::sprintf("  span %s .. %s s  %-6s %-8s -> %s\n", time(span["start_s"], "   -inf"),
                         time(span["end_s"], "    inf"), span["kind"].get<std::string>(),
                         span["required"].get<bool>() ? "required" : "optional",
                         span["node"].is_null() ? std::string("-") : "node " + span["node"].dump());
  }
}

void PrintLoopClosures(const nlohmann::json& l, std::string* out) {
  *out += fmt::sprintf("loop closures (paper 002 Table III), same place within %.1f m and %.0f deg\n",
                       l["radius_m"].get<double>(), l["max_heading_deg"].get<double>());
  *out += fmt::sprintf("%6s %9s %6s %9s %6s %10s %7s\n", "nodes", "possible", "found", "reported", "false", "precision",
                       "recall");
  *out += fmt::sprintf("%6d %9d %6d %9d %6d %s %s\n", l["nodes"].get<int>(), l["possible"].get<int>(),
                       l["found"].get<int>(), l["reported"].get<int>(), l["false_positives"].get<int>(),
                       Score(l["precision"].get<double>(), l["reported"].get<int>() > 0, 10),
                       Score(l["recall"].get<double>(), l["possible"].get<int>() > 0, 7));
}

}  // namespace

std::string RunScoreTables(const nlohmann::json& score, bool spans) {
  std::string out;
  if (score.contains("key_locations")) PrintKeyLocations(score["key_locations"], spans, &out);
  if (score.contains("loop_closures")) PrintLoopClosures(score["loop_closures"], &out);
  if (score.contains("changes")) PrintChangeTable(score["changes"], &out);
  return out;
}

}  // namespace patrolmap::eval
