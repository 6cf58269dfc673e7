#include <algorithm>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>

#include "export_common.h"
#include "patrolmap/graph/export.h"

namespace patrolmap::graph {

std::string Precise(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string EscapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Base64(const std::vector<unsigned char>& bytes) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned value =
        (bytes[i] << 16) | ((i + 1 < bytes.size() ? bytes[i + 1] : 0) << 8) | (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += kAlphabet[(value >> 18) & 63];
    out += kAlphabet[(value >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(value >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[value & 63] : '=';
  }
  return out;
}

std::string PngDataUri(const cv::Mat& image) {
  std::vector<unsigned char> png;
  if (image.empty() || !cv::imencode(".png", image, png)) return "";
  return "data:image/png;base64," + Base64(png);
}

bool HasGps(const TopoMap& map) {
  for (int i = 0; i < map.node_count(); ++i) {
    if (map.node(i).gps) return true;
  }
  return false;
}

std::vector<std::vector<Eigen::Vector2d>> FlightTracks(const TopoMap& map) {
  const std::vector<std::string> flights = map.Flights();
  std::vector<std::vector<Eigen::Vector2d>> tracks(flights.size());
  for (std::size_t f = 0; f < flights.size(); ++f) {
    const PatrolRecord* record = map.Patrol(flights[f]);
    for (std::size_t k = 0; record != nullptr && k < record->route.size(); ++k) {
      if (record->route[k].gps) tracks[f].push_back(*record->route[k].gps);
    }
    if (tracks[f].size() >= 2) continue;
    tracks[f].clear();
    for (int i = 0; i < map.node_count(); ++i) {
      if (map.node(i).flight == flights[f] && map.node(i).gps) tracks[f].push_back(*map.node(i).gps);
    }
  }
  return tracks;
}

std::string JsonForScript(const nlohmann::json& value) {
  const std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<')
      out += "\\u003c";
    else if (c == '>')
      out += "\\u003e";
    else if (c == '&')
      out += "\\u0026";
    else
      out += c;
  }
  return out;
}

}  // namespace patrolmap::graph
