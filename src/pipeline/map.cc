#include "patrolmap/pipeline/map.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "patrolmap/core/files.h"

namespace patrolmap::pipeline {
namespace {

bool Selected(const KeyFrameSelection& selection, std::int64_t frame, int step) {
  if (selection.every_frame) return frame % step == 0;
  return std::binary_search(selection.frames.begin(), selection.frames.end(), frame);
}

void Record(const place::KeyFrame& key_frame, const place::PlaceResult& place, std::map<int, std::int64_t>* frame_of,
            MapResult* result) {
  result->nodes.push_back({place.node, key_frame.flight, key_frame.timestamp_ns, key_frame.frame_index, place.features});
  (*frame_of)[place.node] = key_frame.frame_index;
  result->seconds_features += place.seconds_features;
  result->seconds_query += place.seconds_query;
  result->seconds_verify += place.seconds_verify;
  result->seconds_add += place.seconds_add;
  if (!place.match) return;
  const auto matched = frame_of->find(place.match->node);
  result->loop_closures.push_back({place.node, place.match->node, key_frame.frame_index,
                                   matched == frame_of->end() ? -1 : matched->second, *place.match});
}

}  // namespace

Status RecognisePlaces(const std::string& log, const Config& config, const KeyFrameSelection& selection,
                       place::PlaceRecognizer* recognizer, MapResult* result, const MapProgress& progress) {
  std::unique_ptr<io::FrameSource> source;
  PATROLMAP_RETURN_IF_ERROR(io::OpenLog(log, config.input, &source));
  const int step = config.flow.frames.step;
  const double scale = config.flow.frames.scale;
  std::map<int, std::int64_t> frame_of;
  for (const MapNode& node : result->nodes) frame_of[node.node] = node.frame_index;
  Frame frame;
  Status status;
  std::int64_t next = 0;
  place::KeyFrame key_frame;
  key_frame.flight = source->info().flight_id;
  while ((status = source->Next(Selected(selection, next, step), &frame)).ok()) {
    next = frame.index + 1;
    if (frame.image.empty() || !Selected(selection, frame.index, step)) continue;
    if (scale < 1.0) cv::resize(frame.image, key_frame.image, cv::Size(), scale, scale, cv::INTER_AREA);
    else key_frame.image = frame.image;
    key_frame.timestamp_ns = frame.timestamp_ns;
    key_frame.frame_index = frame.index;
    place::PlaceResult place;
    PATROLMAP_RETURN_IF_ERROR(recognizer->AddKeyFrame(key_frame, &place));
    Record(key_frame, place, &frame_of, result);
    if (progress) progress(frame.index, source->info().frame_count);
  }
  return status.end_of_stream() ? Status::Ok() : status;
}

Status WriteMapOutputs(const MapResult& result, const std::string& folder) {
  PATROLMAP_RETURN_IF_ERROR(EnsureDirectory(folder));
  std::ostringstream nodes, closures;
  nodes << "node,flight,timestamp_ns,frame_index,features\n";
  for (const MapNode& n : result.nodes) {
    nodes << n.node << "," << n.flight << "," << n.timestamp_ns << "," << n.frame_index << "," << n.features << "\n";
  }
  closures << "query_node,matched_node,query_frame,matched_frame,bow_score,matched_fraction,inliers\n";
  char line[256];
  for (const MapLoopClosure& c : result.loop_closures) {
    std::snprintf(line, sizeof(line), "%d,%d,%lld,%lld,%.4f,%.4f,%d\n", c.query_node, c.matched_node,
                  static_cast<long long>(c.query_frame), static_cast<long long>(c.matched_frame),
                  c.verification.bow_score, c.verification.matched_fraction, c.verification.inliers);
    closures << line;
  }
  PATROLMAP_RETURN_IF_ERROR(WriteFileAtomically(folder + "/nodes.csv", nodes.str()));
  return WriteFileAtomically(folder + "/loop_closures.csv", closures.str());
}

}  // namespace patrolmap::pipeline
