// CSV tables and the SVG plot of a detection run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "patrolmap/eval/key_location_score.h"
#include "patrolmap/pipeline/detect.h"

namespace patrolmap::pipeline {
namespace {

std::string CsvNumber(double value) {
  if (std::isnan(value)) return "nan";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", value);
  return buffer;
}

// Maps time and response onto the plot area.
struct PlotFrame {
  double t0 = 0.0, t1 = 1.0, y0 = 0.0, y1 = 1.0;
  double left = 90.0, right = 1140.0, top = 40.0, bottom = 330.0;
  double X(double t) const { return left + (t - t0) / (t1 - t0) * (right - left); }
  double Y(double y) const { return bottom - (y - y0) / (y1 - y0) * (bottom - top); }
};

PlotFrame FitFrame(const std::vector<FlowSample>& samples) {
  PlotFrame frame;
  frame.t0 = NsToSeconds(samples.front().timestamp_ns);
  frame.t1 = std::max(frame.t0 + 1e-3, NsToSeconds(samples.back().timestamp_ns));
  double high = 0.0;
  for (const FlowSample& sample : samples) {
    if (!std::isnan(sample.raw_response)) high = std::max(high, sample.raw_response);
  }
  frame.y0 = std::min(0.0, high);
  frame.y1 = high > 0.0 ? high * 1.05 : 1.0;
  return frame;
}

void Polyline(const std::vector<FlowSample>& samples, const PlotFrame& frame, bool smoothed, const char* style,
              std::ostringstream* svg) {
  *svg << "<polyline fill='none' " << style << " points='";
  for (const FlowSample& sample : samples) {
    const double value = smoothed ? sample.smoothed_response : sample.raw_response;
    if (std::isnan(value)) continue;
    *svg << CsvNumber(frame.X(NsToSeconds(sample.timestamp_ns))) << "," << CsvNumber(frame.Y(value)) << " ";
  }
  *svg << "'/>\n";
}

// A round tick spacing (1, 2 or 5 times a power of ten) giving about `count` ticks over `range`.
double NiceStep(double range, int count) {
  const double raw = range / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double factor : {1.0, 2.0, 5.0}) {
    if (raw <= factor * power) return factor * power;
  }
  return 10.0 * power;
}

void Axes(const PlotFrame& frame, std::ostringstream* svg) {
  *svg << "<rect x='" << frame.left << "' y='" << frame.top << "' width='" << frame.right - frame.left << "' height='"
       << frame.bottom - frame.top << "' fill='white' stroke='#444'/>\n";
  const double t_step = NiceStep(frame.t1 - frame.t0, 10);
  for (double t = std::ceil(frame.t0 / t_step) * t_step; t <= frame.t1; t += t_step) {
    *svg << "<text x='" << CsvNumber(frame.X(t)) << "' y='" << frame.bottom + 16
         << "' font-size='11' text-anchor='middle'>" << CsvNumber(t) << "</text>\n";
  }
  const double y_step = NiceStep(frame.y1 - frame.y0, 5);
  for (double y = std::ceil(frame.y0 / y_step) * y_step; y <= frame.y1; y += y_step) {
    *svg << "<text x='" << frame.left - 6 << "' y='" << CsvNumber(frame.Y(y) + 4)
         << "' font-size='11' text-anchor='end'>" << CsvNumber(y) << "</text>\n";
  }
  *svg << "<text x='" << (frame.left + frame.right) / 2 << "' y='" << frame.bottom + 34
       << "' font-size='12' text-anchor='middle'>time [s]</text>\n"
       << "<text x='18' y='" << (frame.top + frame.bottom) / 2 << "' font-size='12' text-anchor='middle' "
       << "transform='rotate(-90 18 " << (frame.top + frame.bottom) / 2 << ")'>response [image widths / s]</text>\n";
}

// A key location: filled by its kind (peak red, valley blue); judged false, a hollow ring with a cross.
void Markers(const DetectionResult& result, const PlotTruth& truth, const PlotFrame& frame, std::ostringstream* svg) {
  for (double t : truth.times_s) {
    *svg << "<line x1='" << CsvNumber(frame.X(t)) << "' x2='" << CsvNumber(frame.X(t)) << "' y1='" << frame.top
         << "' y2='" << frame.bottom << "' stroke='#2a9d3a' stroke-dasharray='4 3'/>\n";
  }
  for (std::size_t k = 0; k < result.key_locations.size(); ++k) {
    const KeyLocation& node = result.key_locations[k];
    const double x = frame.X(NsToSeconds(node.timestamp_ns)), y = frame.Y(node.response);
    const char* colour = node.kind == ExtremumKind::kPeak ? "#d62828" : "#1d4ed8";
    const bool wrong = k < truth.correct.size() && !truth.correct[k];
    const int id = k < truth.node_ids.size() ? truth.node_ids[k] : node.node_index;
    if (wrong) {
      *svg << "<circle class='false' cx='" << CsvNumber(x) << "' cy='" << CsvNumber(y)
           << "' r='6' fill='white' stroke='" << colour << "' stroke-width='2'/><path d='M" << CsvNumber(x - 4) << ","
           << CsvNumber(y - 4) << " l8,8 m0,-8 l-8,8'"
           << " stroke='" << colour << "' stroke-width='1.5'/>";
    } else {
      *svg << "<circle cx='" << CsvNumber(x) << "' cy='" << CsvNumber(y) << "' r='6' fill='" << colour << "'/>";
    }
    *svg << "<text x='" << CsvNumber(x) << "' y='" << CsvNumber(y - 10) << "' font-size='11' text-anchor='middle'>"
         << (id >= 0 ? std::to_string(id) : std::string("-")) << "</text>\n";
  }
}

void Legend(const PlotFrame& frame, const PlotTruth& truth, std::ostringstream* svg) {
  const double x = frame.left + 10, y = frame.top + 14;
  *svg << "<g font-size='11'>"
       << "<line x1='" << x << "' x2='" << x + 20 << "' y1='" << y << "' y2='" << y << "' stroke='#999'/>"
       << "<text x='" << x + 24 << "' y='" << y + 4 << "'>raw</text>"
       << "<line x1='" << x + 60 << "' x2='" << x + 80 << "' y1='" << y << "' y2='" << y
       << "' stroke='black' stroke-width='2'/><text x='" << x + 84 << "' y='" << y + 4 << "'>smoothed</text>"
       << "<circle cx='" << x + 150 << "' cy='" << y << "' r='5' fill='#d62828'/><text x='" << x + 158 << "' y='"
       << y + 4 << "'>peak</text>"
       << "<circle cx='" << x + 200 << "' cy='" << y << "' r='5' fill='#1d4ed8'/><text x='" << x + 208 << "' y='"
       << y + 4 << "'>valley</text>";
  if (!truth.times_s.empty()) {
    *svg << "<line x1='" << x + 255 << "' x2='" << x + 275 << "' y1='" << y << "' y2='" << y
         << "' stroke='#2a9d3a' stroke-dasharray='4 3'/><text x='" << x + 279 << "' y='" << y + 4
         << "'>ground-truth edge</text><circle cx='" << x + 390 << "' cy='" << y << "' r='5' fill='white' "
         << "stroke='#444' stroke-width='2'/><text x='" << x + 398 << "' y='" << y + 4 << "'>false key location</text>";
  }
  *svg << "<text x='" << x + (truth.times_s.empty() ? 255 : 515) << "' y='" << y + 4 << "'>"
       << (truth.node_ids.empty() ? "numbers: key locations" : "numbers: node ids of nodes.csv") << "</text></g>\n";
}

}  // namespace

std::string KeyLocationsCsv(const std::vector<KeyLocation>& key_locations) {
  std::ostringstream csv;
  csv << "node,timestamp_ns,frame_index,response,kind\n";
  for (const KeyLocation& node : key_locations) {
    csv << node.node_index << "," << node.timestamp_ns << "," << node.frame_index << "," << CsvNumber(node.response)
        << "," << ToString(node.kind) << "\n";
  }
  return csv.str();
}

std::string ResponseCsv(const std::vector<FlowSample>& samples) {
  std::ostringstream csv;
  csv << "timestamp_ns,frame_index,raw_response,smoothed_response,tracked_vectors,accepted_vectors\n";
  for (const FlowSample& sample : samples) {
    csv << sample.timestamp_ns << "," << sample.frame_index << "," << CsvNumber(sample.raw_response) << ","
        << CsvNumber(sample.smoothed_response) << "," << sample.tracked_vectors << "," << sample.accepted_vectors
        << "\n";
  }
  return csv.str();
}

PlotTruth LoadPlotTruth(const std::string& log, const std::vector<KeyLocation>& key_locations) {
  PlotTruth truth;
  std::vector<eval::TruthEdge> edges;
  if (!eval::ReadTruthEdges(log, &edges).ok()) return truth;
  for (const eval::TruthEdge& edge : edges) truth.times_s.push_back(NsToSeconds(edge.timestamp_ns));
  const eval::KeyLocationScore score = eval::ScoreKeyLocations(key_locations, edges);
  for (eval::Verdict verdict : score.verdicts) truth.correct.push_back(verdict == eval::Verdict::kTruePositive);
  return truth;
}

std::string ResponsePlotSvg(const DetectionResult& result, const PlotTruth& truth) {
  std::ostringstream svg;
  svg << "<?xml version='1.0' encoding='UTF-8'?>\n"
      << "<svg xmlns='http://www.w3.org/2000/svg' width='1160' height='380' font-family='sans-serif'>\n"
      << "<rect width='100%' height='100%' fill='#f4f4f4'/>\n"
      << "<text x='580' y='22' font-size='14' text-anchor='middle'>scene-flow response: " << result.key_locations.size()
      << (result.key_locations.size() == 1 ? " key location" : " key locations") << "</text>\n";
  if (!result.samples.empty()) {
    const PlotFrame frame = FitFrame(result.samples);
    Axes(frame, &svg);
    Polyline(result.samples, frame, false, "stroke='#999' stroke-width='1'", &svg);
    Polyline(result.samples, frame, true, "stroke='black' stroke-width='2'", &svg);
    Markers(result, truth, frame, &svg);
    Legend(frame, truth, &svg);
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace patrolmap::pipeline
