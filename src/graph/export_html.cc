// The map viewer: one self-contained HTML page around the layout picture (export_svg.cc).
#include <sstream>

#include <nlohmann/json.hpp>

#include "export_common.h"
#include "patrolmap/core/words.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {
namespace {

nlohmann::json PageData(const TopoMap& map, const std::vector<ClosureMatches>* matches) {
  nlohmann::json nodes = nlohmann::json::array(), closures = nlohmann::json::array();
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    nodes.push_back({{"flight", n.flight},
                     {"time_s", NsToSeconds(n.timestamp_ns)},
                     {"frame", n.frame_index},
                     {"thumbnail", PngDataUri(n.thumbnail)},
                     {"closures", nlohmann::json::array()}});
  }
  for (const TopoMap::Edge& e : map.Edges()) {
    if (e.data.kind != EdgeKind::kLoopClosure) continue;
    const std::size_t k = closures.size();
    nlohmann::json pairs = nlohmann::json::array();
    if (matches != nullptr && k < matches->size()) {
      for (const std::array<float, 4>& p : (*matches)[k].pairs) pairs.push_back({p[0], p[1], p[2], p[3]});
    }
    closures.push_back({{"a", e.a}, {"b", e.b}, {"inliers", e.data.inliers}, {"matches", pairs}});
    nodes[e.a]["closures"].push_back({{"node", e.b}, {"inliers", e.data.inliers}, {"closure", k}});
    nodes[e.b]["closures"].push_back({{"node", e.a}, {"inliers", e.data.inliers}, {"closure", k}});
  }
  return {{"nodes", nodes}, {"closures", closures}};
}

constexpr char kStyle[] = R"(
body{font-family:system-ui,sans-serif;margin:0;display:flex;height:100vh;color:#1f2933}
#map{flex:1;min-width:0;border-right:1px solid #d9dee4}#map svg{width:100%;height:100%;cursor:grab;display:block}
#side{width:380px;padding:12px;overflow:auto;box-sizing:border-box}h3{margin:0 0 6px}
#thumb{width:100%;image-rendering:pixelated;background:#eee;min-height:80px}
#pair{width:100%;background:#eee;display:none}.node,.closure{cursor:pointer}
.legend div{font-size:12px;margin:2px 0}.swatch{display:inline-block;width:18px;height:4px;vertical-align:middle;
margin-right:6px}.muted{color:#52606d;font-size:13px}
)";

constexpr char kScript[] = R"(
const data = JSON.parse(document.getElementById('data').textContent);
const nodes = data.nodes, closures = data.closures;
const svg = document.querySelector('#map svg');
svg.removeAttribute('width'); svg.removeAttribute('height');
let box = svg.viewBox.baseVal;
let drag = null;
svg.addEventListener('mousedown', e => { drag = {x: e.clientX, y: e.clientY}; });
window.addEventListener('mouseup', () => { drag = null; });
svg.addEventListener('mousemove', e => {
  if (!drag) return;
  const k = box.width / svg.clientWidth;
  box.x -= (e.clientX - drag.x) * k; box.y -= (e.clientY - drag.y) * k;
  drag = {x: e.clientX, y: e.clientY};
});
svg.addEventListener('wheel', e => {
  e.preventDefault();
  const f = e.deltaY > 0 ? 1.15 : 1 / 1.15;
  box.x += box.width * (1 - f) / 2; box.y += box.height * (1 - f) / 2; box.width *= f; box.height *= f;
});
const title = document.getElementById('title'), thumb = document.getElementById('thumb');
const pair = document.getElementById('pair'), about = document.getElementById('about');
function describe(i) { const n = nodes[i]; return 'node ' + i + ' (' + n.flight + ', ' + n.time_s.toFixed(1) + ' s, frame ' + n.frame + ')'; }
function showNode(i) {
  const n = nodes[i];
  title.textContent = describe(i);
  thumb.src = n.thumbnail; thumb.style.display = 'block'; pair.style.display = 'none';
  about.textContent = n.closures.length ?
      'loop closures: ' + n.closures.map(c => 'node ' + c.node + ' (' + c.inliers + ' inliers)').join(', ') +
      '. Click a closure to see the pair.' : 'no loop closure';
}
function load(src) { return new Promise(done => { const im = new Image(); im.onload = () => done(im); im.src = src; }); }
async function showClosure(k) {
  const c = closures[k];
  title.textContent = describe(c.a) + ' and ' + describe(c.b);
  about.textContent = c.inliers + ' inliers at mapping; ' + c.matches.length + ' verified matches drawn.';
  const [a, b] = await Promise.all([load(nodes[c.a].thumbnail), load(nodes[c.b].thumbnail)]);
  const gap = 8, s = 2;
  pair.width = (a.width + gap + b.width) * s; pair.height = Math.max(a.height, b.height) * s;
  const g = pair.getContext('2d');
  g.imageSmoothingEnabled = false;
  g.drawImage(a, 0, 0, a.width * s, a.height * s);
  g.drawImage(b, (a.width + gap) * s, 0, b.width * s, b.height * s);
  g.strokeStyle = 'rgba(22,163,74,0.8)'; g.lineWidth = 1.5;
  for (const m of c.matches) {
    g.beginPath(); g.moveTo(m[0] * s, m[1] * s); g.lineTo((a.width + gap + m[2]) * s, m[3] * s); g.stroke();
  }
  thumb.style.display = 'none'; pair.style.display = 'block';
}
document.querySelectorAll('#map .node').forEach(c => c.addEventListener('click', () => showNode(+c.dataset.node)));
document.querySelectorAll('#map .closure').forEach(c => c.addEventListener('click', () => showClosure(+c.dataset.edge)));
const asked = /^#(node|closure)=(\d+)$/.exec(location.hash);  // a link to one: page.html#closure=2
if (asked && asked[1] === 'closure' && +asked[2] < closures.length) showClosure(+asked[2]);
else if (asked && +asked[2] < nodes.length) showNode(+asked[2]);
else if (nodes.length) showNode(0);
document.body.dataset.ready = nodes.length + ' nodes, ' + closures.length + ' loop closures';
)";

void HtmlLegend(const TopoMap& map, const SvgTruth* truth, std::ostringstream* out) {
  const std::vector<std::string> flights = map.Flights();
  *out << "<div class='legend'>";
  for (std::size_t f = 0; f < flights.size(); ++f) {
    *out << "<div><i class='swatch' style='background:" << kFlightColours[f % 5] << "'></i>" << EscapeXml(flights[f])
         << "</div>";
  }
  *out << "<div><i class='swatch' style='background:#16a34a'></i>"
       << (truth != nullptr ? "correct loop closure" : "loop closure") << " (a ring: both nodes at one spot)</div>";
  if (truth != nullptr) {
    *out << "<div><i class='swatch' style='background:#dc2626'></i>false loop closure</div>"
         << "<div><i class='swatch' style='background:#2563eb'></i>missed loop closure</div>";
  }
  *out << "</div>";
}

}  // namespace

std::string ToHtml(const TopoMap& map, const SvgTruth* truth, const std::vector<ClosureMatches>* matches) {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>patrolmap map</title>\n<style>" << kStyle
      << "</style></head>\n<body>\n<div id='map'>" << SvgDrawing(map, truth, false) << "</div>\n<div id='side'><h3>"
      << "patrolmap</h3><p class='muted'>" << Counted(map.node_count(), "node", "nodes") << ", "
      << Counted(map.loop_closure_count(), "loop closure", "loop closures") << ", "
      << Counted(static_cast<long long>(map.Flights().size()), "flight", "flights")
      << ". Drag to pan, wheel to zoom; click a node or a loop closure.</p>";
  HtmlLegend(map, truth, &out);
  out << "<p id='title'></p><img id='thumb' alt=''><canvas id='pair'></canvas><p id='about' class='muted'></p>"
      << "</div>\n<script type='application/json' id='data'>" << JsonForScript(PageData(map, matches))
      << "</script>\n<script>" << kScript << "</script>\n</body></html>\n";
  return out.str();
}

}  // namespace patrolmap::graph
