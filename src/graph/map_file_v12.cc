#include "map_file_v12.h"

#include <set>
#include <tuple>

#include "map_codec.h"
#include "patrolmap/core/checksum.h"
#include "patrolmap/core/files.h"

namespace patrolmap::graph {
namespace {

// 2: PTRL section (patrol records); 3: VOCB section (vocabulary); 4: voxels the grid's memory budget dropped;
// 5: the patrol's depth source; 6: the frames kept along the route; 7: whether the patrol's log was timed;
// 8: features keep their positions only (no size, angle, response, octave), descriptors may be packed 4-bit;
// 9: where the patrol's camera poses came from; 10: the patrol's lens distortion; 11: the patrol's log and its digest;
// 12: each object's site id
constexpr std::uint32_t kOldestVersion = 1;

// A feature as map format 7 and older kept it; only the position is read.
struct KeyPointRecord {
  float x, y, size, angle, response;
  std::int32_t octave;
};

void NodeSection(const TopoMap& map, Writer* w) {
  w->Value(static_cast<std::uint32_t>(map.node_count()));
  for (int i = 0; i < map.node_count(); ++i) {
    const KeyFrameNode& n = map.node(i);
    w->String(n.flight);
    w->Value(n.timestamp_ns);
    w->Value(n.frame_index);
    w->Mat(n.thumbnail);
    w->Value(static_cast<std::uint8_t>(n.gps.has_value()));
    const Eigen::Vector2d gps = n.gps.value_or(Eigen::Vector2d::Zero());
    for (double v : {gps.x(), gps.y(), n.layout.x(), n.layout.y(), n.heading}) w->Value(v);
  }
}

void EdgeSection(const TopoMap& map, Writer* w) {
  const std::vector<TopoMap::Edge> edges = map.Edges();
  w->Value(static_cast<std::uint32_t>(edges.size()));
  for (const TopoMap::Edge& e : edges) {
    w->Value(static_cast<std::uint32_t>(e.a));
    w->Value(static_cast<std::uint32_t>(e.b));
    w->Value(static_cast<std::uint8_t>(e.data.kind));
    w->Value(e.data.bow_score);
    w->Value(e.data.matched_fraction);
    w->Value(static_cast<std::int32_t>(e.data.inliers));
    w->Value(e.data.log_nfa);
  }
}

void FeatureSection(const TopoMap& map, Writer* w) {
  w->Value(static_cast<std::uint32_t>(map.node_count()));
  for (int i = 0; i < map.node_count(); ++i) WriteFeatures(map.node(i), w);
}

void WriteObject(const MapObject& o, Writer* w) {
  w->Value<std::int32_t>(o.id);
  w->String(o.label);
  w->Value(o.confidence);
  w->Value<std::int32_t>(o.detections);
  w->Value<std::uint8_t>(o.confirmed ? 1 : 0);
  for (int k = 0; k < 3; ++k) w->Value(o.centroid[k]);
  WriteObjectShape(o, w);
  w->Value(o.first_seen_ns);
  w->Value(o.last_seen_ns);
}

MapObject ReadObject(Reader* r) {
  MapObject o;
  o.id = r->Value<std::int32_t>();
  o.label = r->String();
  o.confidence = r->Value<double>();
  o.detections = r->Value<std::int32_t>();
  o.confirmed = r->Value<std::uint8_t>() != 0;
  for (int k = 0; k < 3; ++k) o.centroid[k] = r->Value<double>();
  ReadObjectShape(r, &o);
  o.first_seen_ns = r->Value<TimestampNs>();
  o.last_seen_ns = r->Value<TimestampNs>();
  return o;
}

// Per frame: time, frame index, flags (1: pose, 2: GPS), the pose, latitude and longitude, the JPEG bytes.
void WriteRoute(const std::vector<RouteFrame>& route, Writer* w) {
  w->Value(static_cast<std::uint32_t>(route.size()));
  for (const RouteFrame& f : route) {
    w->Value(f.timestamp_ns);
    w->Value(f.frame_index);
    w->Value<std::uint8_t>((f.pose ? 1 : 0) | (f.gps ? 2 : 0));
    w->Value(ToRecord(f.pose.value_or(CameraPoseSample())));
    const Eigen::Vector2d gps = f.gps.value_or(Eigen::Vector2d::Zero());
    w->Value(gps.x());
    w->Value(gps.y());
    w->Vector(f.jpeg);
  }
}

std::vector<RouteFrame> ReadRoute(Reader* r) {
  std::vector<RouteFrame> route;
  const std::uint32_t count = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    RouteFrame f;
    f.timestamp_ns = r->Value<TimestampNs>();
    f.frame_index = r->Value<std::int64_t>();
    const auto flags = r->Value<std::uint8_t>();
    const PoseRecord pose = r->Value<PoseRecord>();
    const double latitude = r->Value<double>(), longitude = r->Value<double>();
    if (flags > 3) f.frame_index = -1;  // not a flag this version writes: ValidRoute refuses the frame
    if ((flags & 1) != 0) f.pose = FromRecord(pose);
    if ((flags & 2) != 0) f.gps = Eigen::Vector2d(latitude, longitude);
    f.jpeg = r->Vector<unsigned char>();
    route.push_back(std::move(f));
  }
  return route;
}

void PatrolSection(const TopoMap& map, Writer* w) {
  w->Value(static_cast<std::uint32_t>(map.patrols().size()));
  for (const PatrolRecord& p : map.patrols()) {
    PATROLMAP_CHECK(!p.partial);
    w->String(p.flight);
    for (double v : {p.camera.fx, p.camera.fy, p.camera.cx, p.camera.cy}) w->Value(v);
    w->Value<std::int32_t>(p.camera.width);
    w->Value<std::int32_t>(p.camera.height);
    w->Value<std::int32_t>(p.feature_image_width);
    w->Vector(ToRecords(p.views));
    w->Value<std::uint8_t>(p.has_objects ? 1 : 0);
    w->Value(static_cast<std::uint32_t>(p.objects.size()));
    for (const MapObject& o : p.objects) WriteObject(o, w);
    w->Value(p.grid.voxel_size);
    w->Vector(p.grid.voxels);
    w->Value<std::int64_t>(p.grid.evicted_voxels);
    w->String(p.depth_source);
    WriteRoute(p.route, w);
    w->Value<std::uint8_t>(p.timed ? 1 : 0);
    w->String(p.pose_source);
    for (double k : p.distortion) w->Value(k);
    w->String(p.source);
    w->String(p.source_digest);
    std::vector<std::int32_t> site_ids;
    for (const MapObject& o : p.objects) site_ids.push_back(o.site_id);
    w->Vector(site_ids);
  }
}

void VocabularySection(const TopoMap& map, Writer* w) {
  w->Value(map.vocabulary().fingerprint);
  w->String(map.vocabulary().name);
}

Status WriteSection(const char (&tag)[5], const TopoMap& map, void (*build)(const TopoMap&, Writer*),
                    AtomicFile* file) {
  std::string payload;
  Writer writer(&payload);
  build(map, &writer);
  std::string header(tag, 4);
  const std::uint64_t size = payload.size(), sum = Checksum(payload.data(), payload.size());
  header.append(reinterpret_cast<const char*>(&size), 8);
  header.append(reinterpret_cast<const char*>(&sum), 8);
  PATROLMAP_RETURN_IF_ERROR(file->Write(header));
  return file->Write(payload);
}

Status ParseNodes(const std::string& path, Reader* r, TopoMap* map) {
  const std::uint32_t count = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    KeyFrameNode n;
    n.flight = r->String();
    n.timestamp_ns = r->Value<TimestampNs>();
    n.frame_index = r->Value<std::int64_t>();
    n.thumbnail = r->Mat();
    const bool has_gps = r->Value<std::uint8_t>() != 0;
    double v[5];
    for (double& value : v) value = r->Value<double>();
    if (has_gps) n.gps = Eigen::Vector2d(v[0], v[1]);
    n.layout = Eigen::Vector2d(v[2], v[3]);
    n.heading = v[4];
    if (!ValidFlightId(n.flight)) return Corrupt(path, "flight id of node " + std::to_string(i));
    if (!r->failed() && !ValidNodeValues(n))
      return Corrupt(path, "time, frame, GPS or layout of node " + std::to_string(i));
    if (!r->failed() && !ValidThumbnail(n.thumbnail)) return Corrupt(path, "thumbnail of node " + std::to_string(i));
    map->AddNode(std::move(n));
  }
  return r->failed() || !r->done() ? Corrupt(path, "node section") : Status::Ok();
}

Status ParseEdges(const std::string& path, std::uint32_t version, Reader* r, TopoMap* map) {
  const std::uint32_t count = r->Value<std::uint32_t>();
  std::set<std::tuple<std::uint32_t, std::uint32_t, std::uint8_t>> seen;
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    const auto a = r->Value<std::uint32_t>(), b = r->Value<std::uint32_t>();
    EdgeData e;
    const auto kind = r->Value<std::uint8_t>();
    e.bow_score = r->Value<double>();
    e.matched_fraction = r->Value<double>();
    e.inliers = r->Value<std::int32_t>();
    if (version >= 3) e.log_nfa = r->Value<double>();
    if (r->failed()) break;
    const int nodes = map->node_count();
    if (kind > 1 || a >= static_cast<std::uint32_t>(nodes) || b >= static_cast<std::uint32_t>(nodes) ||
        !ValidEdge(e, static_cast<int>(a), static_cast<int>(b), nodes)) {
      return Corrupt(path, "edge " + std::to_string(i));
    }
    // A map holds one edge of a kind between two nodes (a crafted one could repeat it thousands of times).
    if (!seen.insert({std::min(a, b), std::max(a, b), kind}).second) {
      return Corrupt(path, "edge " + std::to_string(i) + " repeats another");
    }
    e.kind = static_cast<EdgeKind>(kind);
    map->AddEdge(static_cast<int>(a), static_cast<int>(b), e);
  }
  return r->failed() || !r->done() ? Corrupt(path, "edge section") : Status::Ok();
}

Status ParseFeatures(const std::string& path, std::uint32_t version, Reader* r, TopoMap* map) {
  if (r->Value<std::uint32_t>() != static_cast<std::uint32_t>(map->node_count())) return Corrupt(path, "feature count");
  for (int i = 0; i < map->node_count() && !r->failed(); ++i) {
    KeyFrameNode& n = map->mutable_node(i);
    if (version >= 8) {
      ReadFeatures(r, &n);
    } else {
      for (const KeyPointRecord& k : r->Vector<KeyPointRecord>()) n.points.emplace_back(k.x, k.y);
      n.descriptors = r->Mat();
      n.bow.words = r->Vector<vocab::WordId>();
      n.bow.weights = r->Vector<float>();
    }
    if (!ValidFeatures(n)) return Corrupt(path, "features of node " + std::to_string(i));
  }
  return r->failed() || !r->done() ? Corrupt(path, "feature section") : Status::Ok();
}

Status ParsePatrols(const std::string& path, std::uint32_t version, Reader* r, TopoMap* map) {
  const std::uint32_t count = r->Value<std::uint32_t>();
  for (std::uint32_t i = 0; i < count && !r->failed(); ++i) {
    PatrolRecord p;
    p.flight = r->String();
    p.camera.fx = r->Value<double>(), p.camera.fy = r->Value<double>();
    p.camera.cx = r->Value<double>(), p.camera.cy = r->Value<double>();
    p.camera.width = r->Value<std::int32_t>(), p.camera.height = r->Value<std::int32_t>();
    p.feature_image_width = r->Value<std::int32_t>();
    p.views = FromRecords(r->Vector<PoseRecord>());
    p.has_objects = r->Value<std::uint8_t>() != 0;
    const std::uint32_t objects = r->Value<std::uint32_t>();
    for (std::uint32_t k = 0; k < objects && !r->failed(); ++k) p.objects.push_back(ReadObject(r));
    p.grid.voxel_size = r->Value<double>();
    p.grid.voxels = r->Vector<VoxelEvidence>();
    if (version >= 4) p.grid.evicted_voxels = r->Value<std::int64_t>();
    if (version >= 5) p.depth_source = r->String();
    if (version >= 6) p.route = ReadRoute(r);
    if (version >= 7) p.timed = r->Value<std::uint8_t>() != 0;
    if (version >= 9) p.pose_source = r->String();
    if (version >= 10)
      for (double& k : p.distortion) k = r->Value<double>();
    if (version >= 11) p.source = r->String(), p.source_digest = r->String();
    if (version >= 12) {
      const std::vector<std::int32_t> site_ids = r->Vector<std::int32_t>();
      if (site_ids.size() != p.objects.size() && !r->failed()) return Corrupt(path, "site objects of " + p.flight);
      for (std::size_t k = 0; k < site_ids.size(); ++k) p.objects[k].site_id = site_ids[k];
    }
    if (r->failed()) break;
    if (!ValidFlightId(p.flight)) return Corrupt(path, "flight id of patrol " + std::to_string(i));
    PATROLMAP_RETURN_IF_ERROR(CheckPatrolRecord(path, p));
    // A second record of one flight would replace the first unseen (SetPatrol); a map never holds two.
    if (map->Patrol(p.flight) != nullptr) return Corrupt(path, "second patrol record of " + p.flight);
    map->SetPatrol(std::move(p));
  }
  return r->failed() || !r->done() ? Corrupt(path, "patrol section") : Status::Ok();
}

Status ParseVocabulary(const std::string& path, Reader* r, TopoMap* map) {
  TopoMap::VocabularyTag tag;
  tag.fingerprint = r->Value<std::uint64_t>();
  tag.name = r->String();
  if (r->failed() || !r->done()) return Corrupt(path, "vocabulary section");
  map->set_vocabulary(std::move(tag));
  return Status::Ok();
}

// Which sections a file has given so far; each may appear once.
struct SectionsSeen {
  bool nodes = false, edges = false, features = false, patrols = false, vocabulary = false;
};

Status ParseSection(const std::string& path, std::uint32_t version, const std::string& tag, const char* payload,
                    std::size_t length, TopoMap* map, SectionsSeen* seen) {
  Reader reader(payload, length);
  const auto once = [&](bool* flag) {
    const bool first = !*flag;
    *flag = true;
    return first;
  };
  if (tag == "NODE" && once(&seen->nodes)) return ParseNodes(path, &reader, map);
  if (tag == "EDGE" && seen->nodes && once(&seen->edges)) return ParseEdges(path, version, &reader, map);
  if (tag == "FEAT" && seen->nodes && once(&seen->features)) return ParseFeatures(path, version, &reader, map);
  if (tag == "PTRL" && once(&seen->patrols)) return ParsePatrols(path, version, &reader, map);
  if (tag == "VOCB" && once(&seen->vocabulary)) return ParseVocabulary(path, &reader, map);
  return Corrupt(path, "unexpected or repeated section " + tag);
}

}  // namespace

Status SaveLegacyMap(const TopoMap& map, const std::string& path) {
  AtomicFile file;
  PATROLMAP_RETURN_IF_ERROR(AtomicFile::Open(path, &file));
  std::string start(kLegacyMagic, 8);
  const std::uint32_t header[2] = {kLegacyVersion, 5};
  start.append(reinterpret_cast<const char*>(header), sizeof(header));
  PATROLMAP_RETURN_IF_ERROR(file.Write(start));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("NODE", map, NodeSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("EDGE", map, EdgeSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("FEAT", map, FeatureSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("PTRL", map, PatrolSection, &file));
  PATROLMAP_RETURN_IF_ERROR(WriteSection("VOCB", map, VocabularySection, &file));
  return file.Commit();
}

Status ParseLegacyMap(const std::string& path, const std::string& bytes, TopoMap* map) {
  const std::size_t size = bytes.size();
  if (size < 16) return Status::DataLoss(path + ": truncated map (header incomplete)");
  std::uint32_t header[2];
  std::memcpy(header, bytes.data() + 8, sizeof(header));
  if (header[0] < kOldestVersion) {
    return Status::DataLoss(path + ": map format version " + std::to_string(header[0]) + " is not one patrolmap wrote");
  }
  if (header[0] > kLegacyVersion) {
    return Status::DataLoss(path + ": map format version " + std::to_string(header[0]) +
                            " is not one patrolmap wrote (maps of version 13 on are SQLite databases)");
  }
  *map = TopoMap();
  std::size_t position = 16;
  SectionsSeen seen;
  for (std::uint32_t s = 0; s < header[1]; ++s) {
    if (size - position < 20)
      return Status::DataLoss(path + ": truncated map (section " + std::to_string(s) + " header)");
    const std::string tag(bytes.data() + position, 4);
    std::uint64_t length, checksum;
    std::memcpy(&length, bytes.data() + position + 4, 8);
    std::memcpy(&checksum, bytes.data() + position + 12, 8);
    position += 20;
    if (length > size - position) return Status::DataLoss(path + ": truncated map (section " + tag + ")");
    const char* payload = bytes.data() + position;
    if (Checksum(payload, length) != checksum) return Corrupt(path, "checksum of section " + tag);
    PATROLMAP_RETURN_IF_ERROR(ParseSection(path, header[0], tag, payload, length, map, &seen));
    position += length;
  }
  if (!seen.nodes || !seen.edges) return Corrupt(path, "node or edge section missing");
  if (position != size) return Corrupt(path, "trailing bytes");
  return Status::Ok();
}

}  // namespace patrolmap::graph
