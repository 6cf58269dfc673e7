#include "patrolmap/graph/map_file.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "map_codec.h"
#include "map_file_v12.h"
#include "patrolmap/core/files.h"
#include "patrolmap/core/option_check.h"
#include "patrolmap/core/sqlite.h"

namespace patrolmap::graph {
namespace {

constexpr std::uint32_t kVersion = 13;  // 13: the SQLite database; 1 to 12: the binary file (map_file_v12.h)
constexpr char kFormat[] = "patrolmap.map";
constexpr char kSqliteMagic[16] = {'S', 'Q', 'L', 'i', 't', 'e', ' ', 'f', 'o', 'r', 'm', 'a', 't', ' ', '3', '\0'};

constexpr char kSchema[] = R"sql(
CREATE TABLE map_info(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE nodes(id INTEGER PRIMARY KEY, flight TEXT NOT NULL, timestamp_ns INTEGER NOT NULL,
  frame_index INTEGER NOT NULL, latitude REAL, longitude REAL, layout_x REAL NOT NULL, layout_y REAL NOT NULL,
  heading REAL NOT NULL, thumbnail BLOB NOT NULL, features BLOB NOT NULL);
CREATE TABLE edges(id INTEGER PRIMARY KEY, node_a INTEGER NOT NULL, node_b INTEGER NOT NULL, kind TEXT NOT NULL,
  bow_score REAL NOT NULL, matched_fraction REAL NOT NULL, inliers INTEGER NOT NULL, log_nfa REAL NOT NULL);
CREATE TABLE patrols(id INTEGER PRIMARY KEY, flight TEXT NOT NULL UNIQUE, fx REAL NOT NULL, fy REAL NOT NULL,
  cx REAL NOT NULL, cy REAL NOT NULL, width INTEGER NOT NULL, height INTEGER NOT NULL, distortion BLOB NOT NULL,
  feature_image_width INTEGER NOT NULL, has_objects INTEGER NOT NULL, depth_source TEXT NOT NULL,
  pose_source TEXT NOT NULL, timed INTEGER NOT NULL, source TEXT NOT NULL, source_digest TEXT NOT NULL,
  views BLOB NOT NULL, voxel_size REAL NOT NULL, evicted_voxels INTEGER NOT NULL, archived INTEGER NOT NULL);
CREATE TABLE objects(patrol INTEGER NOT NULL, position INTEGER NOT NULL, id INTEGER NOT NULL,
  site_object INTEGER NOT NULL, label TEXT NOT NULL, confidence REAL NOT NULL, detections INTEGER NOT NULL,
  confirmed INTEGER NOT NULL, x REAL NOT NULL, y REAL NOT NULL, z REAL NOT NULL, first_seen_ns INTEGER NOT NULL,
  last_seen_ns INTEGER NOT NULL, shape BLOB NOT NULL, PRIMARY KEY(patrol, position));
CREATE TABLE grids(patrol INTEGER PRIMARY KEY, voxels BLOB NOT NULL);
CREATE TABLE route_frames(patrol INTEGER NOT NULL, position INTEGER NOT NULL, timestamp_ns INTEGER NOT NULL,
  frame_index INTEGER NOT NULL, x REAL, y REAL, z REAL, qw REAL, qx REAL, qy REAL, qz REAL, latitude REAL,
  longitude REAL, jpeg BLOB NOT NULL, PRIMARY KEY(patrol, position));
)sql";

const char* KindName(EdgeKind kind) { return kind == EdgeKind::kLoopClosure ? "loop_closure" : "traversal"; }

std::string Hex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// The first bytes of `path`, at most `count`.
std::string FileStart(const std::string& path, std::size_t count) {
  std::string bytes(count, '\0');
  std::ifstream in(path, std::ios::binary);
  in.read(bytes.data(), static_cast<std::streamsize>(count));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

bool IsDatabase(const std::string& path) { return FileStart(path, 16) == std::string(kSqliteMagic, 16); }

template <typename T>
std::string Bytes(const T& value, void (*write)(const T&, Writer*)) {
  std::string bytes;
  Writer writer(&bytes);
  write(value, &writer);
  return bytes;
}

// ---- Writing ----

class MapWriter {
 public:
  explicit MapWriter(SqliteDatabase* db) : db_(db) {}

  Status Prepare() {
    PATROLMAP_RETURN_IF_ERROR(
        db_->Prepare("INSERT INTO nodes VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)", &node_));
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare("INSERT INTO edges VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)", &edge_));
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "INSERT INTO patrols VALUES(NULL, ?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, "
        "?18, ?19)",
        &patrol_));
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "INSERT INTO objects VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14)", &object_));
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare("INSERT INTO grids VALUES(?1, ?2)", &grid_));
    return db_->Prepare("INSERT INTO route_frames VALUES(?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14)",
                        &frame_);
  }

  Status Info(const TopoMap& map) {
    SqliteStatement info;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare("INSERT OR REPLACE INTO map_info VALUES(?1, ?2)", &info));
    const std::pair<const char*, std::string> rows[] = {{"format", kFormat},
                                                        {"version", std::to_string(kVersion)},
                                                        {"vocabulary_fingerprint", Hex(map.vocabulary().fingerprint)},
                                                        {"vocabulary_name", map.vocabulary().name}};
    for (const auto& [key, value] : rows)
      PATROLMAP_RETURN_IF_ERROR(info.Bind(1, std::string(key)).Bind(2, value).Run());
    return Status::Ok();
  }

  Status Node(int id, const KeyFrameNode& n) {
    node_.Bind(1, static_cast<std::int64_t>(id)).Bind(2, n.flight).Bind(3, std::int64_t{n.timestamp_ns});
    node_.Bind(4, std::int64_t{n.frame_index});
    if (n.gps) {
      node_.Bind(5, n.gps->x()).Bind(6, n.gps->y());
    } else {
      node_.BindNull(5).BindNull(6);
    }
    node_.Bind(7, n.layout.x()).Bind(8, n.layout.y()).Bind(9, n.heading);
    const std::string thumbnail = Bytes<cv::Mat>(n.thumbnail, [](const cv::Mat& m, Writer* w) { w->Mat(m); });
    const std::string features = Bytes<KeyFrameNode>(n, WriteFeatures);
    node_.BindBlob(10, thumbnail.data(), thumbnail.size()).BindBlob(11, features.data(), features.size());
    return node_.Run();
  }

  Status Edge(int id, const TopoMap::Edge& e) {
    edge_.Bind(1, static_cast<std::int64_t>(id)).Bind(2, static_cast<std::int64_t>(e.a));
    edge_.Bind(3, static_cast<std::int64_t>(e.b)).Bind(4, std::string(KindName(e.data.kind)));
    edge_.Bind(5, e.data.bow_score).Bind(6, e.data.matched_fraction);
    edge_.Bind(7, static_cast<std::int64_t>(e.data.inliers)).Bind(8, e.data.log_nfa);
    return edge_.Run();
  }

  // A whole record, with its objects, grid and route frames.
  Status Patrol(const PatrolRecord& p) {
    PATROLMAP_CHECK(!p.partial);
    const CameraIntrinsics& c = p.camera;
    patrol_.Bind(1, p.flight).Bind(2, c.fx).Bind(3, c.fy).Bind(4, c.cx).Bind(5, c.cy);
    patrol_.Bind(6, static_cast<std::int64_t>(c.width)).Bind(7, static_cast<std::int64_t>(c.height));
    patrol_.BindBlob(8, p.distortion.data(), sizeof(p.distortion));
    patrol_.Bind(9, static_cast<std::int64_t>(p.feature_image_width)).Bind(10, std::int64_t{p.has_objects});
    patrol_.Bind(11, p.depth_source).Bind(12, p.pose_source).Bind(13, std::int64_t{p.timed});
    patrol_.Bind(14, p.source).Bind(15, p.source_digest);
    const std::vector<PoseRecord> views = ToRecords(p.views);
    patrol_.BindBlob(16, views.data(), views.size() * sizeof(PoseRecord));
    patrol_.Bind(17, p.grid.voxel_size).Bind(18, static_cast<std::int64_t>(p.grid.evicted_voxels));
    patrol_.Bind(19, std::int64_t{p.archived});
    PATROLMAP_RETURN_IF_ERROR(patrol_.Run());
    const std::int64_t row = LastRow();
    for (std::size_t i = 0; i < p.objects.size(); ++i) PATROLMAP_RETURN_IF_ERROR(Object(row, i, p.objects[i]));
    grid_.Bind(1, row).BindBlob(2, p.grid.voxels.data(), p.grid.voxels.size() * sizeof(VoxelEvidence));
    PATROLMAP_RETURN_IF_ERROR(grid_.Run());
    for (std::size_t i = 0; i < p.route.size(); ++i) PATROLMAP_RETURN_IF_ERROR(Frame(row, i, p.route[i]));
    return Status::Ok();
  }

 private:
  std::int64_t LastRow() {
    SqliteStatement last;
    Status status;
    if (!db_->Prepare("SELECT last_insert_rowid()", &last).ok() || !last.Step(&status)) return -1;
    return last.Int(0);
  }

  Status Object(std::int64_t patrol, std::size_t position, const MapObject& o) {
    object_.Bind(1, patrol).Bind(2, static_cast<std::int64_t>(position)).Bind(3, static_cast<std::int64_t>(o.id));
    object_.Bind(4, static_cast<std::int64_t>(o.site_id)).Bind(5, o.label).Bind(6, o.confidence);
    object_.Bind(7, static_cast<std::int64_t>(o.detections)).Bind(8, std::int64_t{o.confirmed});
    object_.Bind(9, o.centroid.x()).Bind(10, o.centroid.y()).Bind(11, o.centroid.z());
    object_.Bind(12, std::int64_t{o.first_seen_ns}).Bind(13, std::int64_t{o.last_seen_ns});
    const std::string shape = Bytes<MapObject>(o, WriteObjectShape);
    object_.BindBlob(14, shape.data(), shape.size());
    return object_.Run();
  }

  Status Frame(std::int64_t patrol, std::size_t position, const RouteFrame& f) {
    frame_.Bind(1, patrol).Bind(2, static_cast<std::int64_t>(position)).Bind(3, std::int64_t{f.timestamp_ns});
    frame_.Bind(4, std::int64_t{f.frame_index});
    if (f.pose) {
      const PoseRecord r = ToRecord(*f.pose);
      for (int k = 0; k < 3; ++k) frame_.Bind(5 + k, r.position[k]);
      for (int k = 0; k < 4; ++k) frame_.Bind(8 + k, r.rotation[k]);
    } else {
      for (int k = 5; k < 12; ++k) frame_.BindNull(k);
    }
    if (f.gps) {
      frame_.Bind(12, f.gps->x()).Bind(13, f.gps->y());
    } else {
      frame_.BindNull(12).BindNull(13);
    }
    frame_.BindBlob(14, f.jpeg.data(), f.jpeg.size());
    return frame_.Run();
  }

  SqliteDatabase* db_;
  SqliteStatement node_, edge_, patrol_, object_, grid_, frame_;
};

// Opens the temporary of `file` as a database written in one transaction; the temporary is flushed and renamed
// by the caller (AtomicFile::Commit), so SQLite keeps no journal of its own. A new database gives the pages an
// archived patrol's grid and frames free back at each save (auto_vacuum, set before its first table), so the file
// holds what the map holds.
Status OpenForWriting(const AtomicFile& file, SqliteDatabase* db) {
  PATROLMAP_RETURN_IF_ERROR(SqliteDatabase::Open(file.temporary_path(), SqliteDatabase::Mode::kReadWrite, db));
  PATROLMAP_RETURN_IF_ERROR(
      db->Execute("PRAGMA auto_vacuum = FULL; PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF;"));
  return db->Execute("BEGIN");
}

Status Finish(SqliteDatabase* db, AtomicFile* file) {
  PATROLMAP_RETURN_IF_ERROR(db->Execute("COMMIT"));
  PATROLMAP_RETURN_IF_ERROR(db->Close());
  return file->Commit();
}

// Copies `from` into `file`, in pieces.
Status CopyInto(const std::string& from, AtomicFile* file) {
  std::ifstream in(from, std::ios::binary);
  if (!in) return Status::NotFound(from + ": cannot read map");
  std::string piece(1 << 20, '\0');
  while (in) {
    in.read(piece.data(), static_cast<std::streamsize>(piece.size()));
    const std::streamsize got = in.gcount();
    if (got > 0) PATROLMAP_RETURN_IF_ERROR(file->Write(piece.data(), static_cast<std::size_t>(got)));
  }
  if (in.bad()) return Status::IoError(from + ": read failed");
  return Status::Ok();
}

std::int64_t Count(SqliteDatabase* db, const std::string& sql, Status* status) {
  SqliteStatement statement;
  *status = db->Prepare(sql, &statement);
  if (!status->ok() || !statement.Step(status)) return -1;
  return statement.Int(0);
}

// ---- Reading ----

class MapReader {
 public:
  MapReader(SqliteDatabase* db, const std::string& path) : db_(db), path_(path) {}

  Status Info(TopoMap* map) {
    std::map<std::string, std::string> info;
    SqliteStatement rows;
    const Status prepared = db_->Prepare("SELECT key, value FROM map_info", &rows);
    if (prepared.message().find("no such table: map_info") != std::string::npos) {
      return Status::DataLoss(path_ + ": an SQLite database, but not a patrolmap map");
    }
    PATROLMAP_RETURN_IF_ERROR(prepared);
    Status status;
    while (rows.Step(&status)) info[rows.Text(0)] = rows.Text(1);
    PATROLMAP_RETURN_IF_ERROR(status);
    if (info["format"] != kFormat) return Status::DataLoss(path_ + ": an SQLite database, but not a patrolmap map");
    const std::string& version = info["version"];
    if (version != std::to_string(kVersion)) {
      const bool number = !version.empty() && version.size() < 10 &&
                          std::all_of(version.begin(), version.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (number && std::stoul(version) > kVersion) {
        return Status::DataLoss(path_ + ": map format version " + version + " is newer than this patrolmap reads (" +
                                std::to_string(kVersion) + ")");
      }
      return Corrupt(path_, "map_info: version '" + version + "'");
    }
    TopoMap::VocabularyTag tag;
    const std::string& fingerprint = info["vocabulary_fingerprint"];
    char* end = nullptr;
    tag.fingerprint = std::strtoull(fingerprint.c_str(), &end, 16);
    if (fingerprint.size() != 16 || end != fingerprint.c_str() + 16) {
      return Corrupt(path_, "map_info: vocabulary_fingerprint");
    }
    tag.name = info["vocabulary_name"];
    map->set_vocabulary(std::move(tag));
    return Status::Ok();
  }

  Status Nodes(TopoMap* map) {
    SqliteStatement rows;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "SELECT id, flight, timestamp_ns, frame_index, latitude, longitude, layout_x, layout_y, heading, thumbnail, "
        "features FROM nodes ORDER BY id",
        &rows));
    Status status;
    while (rows.Step(&status)) {
      const std::string where = "node " + std::to_string(map->node_count());
      if (rows.Int(0) != map->node_count()) return Corrupt(path_, "node ids: not 0, 1, 2, ... at " + where);
      KeyFrameNode n;
      n.flight = rows.Text(1);
      n.timestamp_ns = rows.Int(2);
      n.frame_index = rows.Int(3);
      if (!rows.IsNull(4) || !rows.IsNull(5)) n.gps = Eigen::Vector2d(rows.Real(4), rows.Real(5));
      n.layout = Eigen::Vector2d(rows.Real(6), rows.Real(7));
      n.heading = rows.Real(8);
      if (!ValidNodeValues(n)) return Corrupt(path_, "flight, time, frame, GPS or layout of " + where);
      Reader thumbnail = BlobReader(rows, 9);
      n.thumbnail = thumbnail.Mat();
      if (thumbnail.failed() || !thumbnail.done() || !ValidThumbnail(n.thumbnail)) {
        return Corrupt(path_, "thumbnail of " + where);
      }
      Reader features = BlobReader(rows, 10);
      ReadFeatures(&features, &n);
      if (features.failed() || !features.done() || !ValidFeatures(n)) return Corrupt(path_, "features of " + where);
      map->AddNode(std::move(n));
    }
    return status;
  }

  Status Edges(TopoMap* map) {
    SqliteStatement rows;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "SELECT node_a, node_b, kind, bow_score, matched_fraction, inliers, log_nfa FROM edges ORDER BY id", &rows));
    std::set<std::tuple<std::int64_t, std::int64_t, bool>> seen;
    Status status;
    for (int i = 0; rows.Step(&status); ++i) {
      const std::int64_t a = rows.Int(0), b = rows.Int(1);
      const std::string kind = rows.Text(2);
      EdgeData e;
      e.kind = kind == "loop_closure" ? EdgeKind::kLoopClosure : EdgeKind::kTraversal;
      e.bow_score = rows.Real(3);
      e.matched_fraction = rows.Real(4);
      e.inliers = static_cast<int>(std::clamp<std::int64_t>(rows.Int(5), -1, 1 << 30));
      e.log_nfa = rows.Real(6);
      const int nodes = map->node_count();
      const bool in_range = a >= 0 && b >= 0 && a < nodes && b < nodes;
      if ((kind != "loop_closure" && kind != "traversal") || !in_range ||
          !ValidEdge(e, static_cast<int>(a), static_cast<int>(b), nodes)) {
        return Corrupt(path_, "edge " + std::to_string(i));
      }
      if (!seen.insert({std::min(a, b), std::max(a, b), e.kind == EdgeKind::kLoopClosure}).second) {
        return Corrupt(path_, "edge " + std::to_string(i) + " repeats another");
      }
      map->AddEdge(static_cast<int>(a), static_cast<int>(b), e);
    }
    return status;
  }

  // The records with their objects; grids and route frames are read by Details. Fills ids_ (patrols.id per record).
  Status Patrols(std::vector<PatrolRecord>* out) {
    SqliteStatement rows;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "SELECT id, flight, fx, fy, cx, cy, width, height, distortion, feature_image_width, has_objects, depth_source, "
        "pose_source, timed, source, source_digest, views, voxel_size, evicted_voxels, archived FROM patrols ORDER BY "
        "id",
        &rows));
    Status status;
    while (rows.Step(&status)) {
      PatrolRecord p;
      ids_.push_back(rows.Int(0));
      p.flight = rows.Text(1);
      CameraIntrinsics& c = p.camera;
      c.fx = rows.Real(2), c.fy = rows.Real(3), c.cx = rows.Real(4), c.cy = rows.Real(5);
      c.width = static_cast<int>(std::clamp<std::int64_t>(rows.Int(6), -1, 1 << 30));
      c.height = static_cast<int>(std::clamp<std::int64_t>(rows.Int(7), -1, 1 << 30));
      std::size_t size = 0;
      const unsigned char* distortion = rows.Blob(8, &size);
      if (size != sizeof(p.distortion)) return Corrupt(path_, "patrols: distortion of " + p.flight);
      std::memcpy(p.distortion.data(), distortion, size);
      p.feature_image_width = static_cast<int>(std::clamp<std::int64_t>(rows.Int(9), -1, 1 << 30));
      p.has_objects = rows.Int(10) != 0;
      p.depth_source = rows.Text(11);
      p.pose_source = rows.Text(12);
      p.timed = rows.Int(13) != 0;
      p.source = rows.Text(14);
      p.source_digest = rows.Text(15);
      const unsigned char* views = rows.Blob(16, &size);
      if (size % sizeof(PoseRecord) != 0) return Corrupt(path_, "patrols: views of " + p.flight);
      std::vector<PoseRecord> records(size / sizeof(PoseRecord));
      if (size > 0) std::memcpy(static_cast<void*>(records.data()), views, size);
      p.views = FromRecords(records);
      p.grid.voxel_size = rows.Real(17);
      p.grid.evicted_voxels = rows.Int(18);
      p.archived = rows.Int(19) != 0;
      out->push_back(std::move(p));
    }
    PATROLMAP_RETURN_IF_ERROR(status);
    return Objects(out);
  }

  // The evidence grid of records[i].
  Status Grid(std::size_t i, PatrolRecord* p) {
    SqliteStatement grid;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare("SELECT voxels FROM grids WHERE patrol = ?1", &grid));
    Status status;
    if (grid.Bind(1, ids_[i]).Step(&status)) {
      std::size_t size = 0;
      const unsigned char* voxels = grid.Blob(0, &size);
      if (size % sizeof(VoxelEvidence) != 0) return Corrupt(path_, "grids: voxels of " + p->flight);
      p->grid.voxels.resize(size / sizeof(VoxelEvidence));
      if (size > 0) std::memcpy(static_cast<void*>(p->grid.voxels.data()), voxels, size);
    }
    return status;
  }

  // The route frames of records[i].
  Status Route(std::size_t i, PatrolRecord* p) { return RouteOf(ids_[i], p); }

 private:
  static Reader BlobReader(const SqliteStatement& rows, int column) {
    std::size_t size = 0;
    const unsigned char* data = rows.Blob(column, &size);
    return Reader(reinterpret_cast<const char*>(data), data == nullptr ? 0 : size);
  }

  Status Objects(std::vector<PatrolRecord>* records) {
    std::map<std::int64_t, std::size_t> index;
    for (std::size_t i = 0; i < ids_.size(); ++i) index[ids_[i]] = i;
    SqliteStatement rows;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "SELECT patrol, id, site_object, label, confidence, detections, confirmed, x, y, z, first_seen_ns, "
        "last_seen_ns, shape FROM objects ORDER BY patrol, position",
        &rows));
    Status status;
    while (rows.Step(&status)) {
      const auto owner = index.find(rows.Int(0));
      if (owner == index.end()) return Corrupt(path_, "objects: an object of no patrol");
      PatrolRecord& p = (*records)[owner->second];
      MapObject o;
      o.id = static_cast<int>(std::clamp<std::int64_t>(rows.Int(1), INT32_MIN, INT32_MAX));
      o.site_id = static_cast<int>(std::clamp<std::int64_t>(rows.Int(2), -2, kMaxSiteId + 1));
      o.label = rows.Text(3);
      o.confidence = rows.Real(4);
      o.detections = static_cast<int>(std::clamp<std::int64_t>(rows.Int(5), -1, INT32_MAX));
      o.confirmed = rows.Int(6) != 0;
      o.centroid = Eigen::Vector3d(rows.Real(7), rows.Real(8), rows.Real(9));
      o.first_seen_ns = rows.Int(10);
      o.last_seen_ns = rows.Int(11);
      Reader shape = BlobReader(rows, 12);
      ReadObjectShape(&shape, &o);
      if (shape.failed() || !shape.done()) {
        return Corrupt(path_, "objects: shape of object " + std::to_string(o.id) + " of patrol " + p.flight);
      }
      p.objects.push_back(std::move(o));
    }
    return status;
  }

  Status RouteOf(std::int64_t patrol, PatrolRecord* p) {
    SqliteStatement rows;
    PATROLMAP_RETURN_IF_ERROR(db_->Prepare(
        "SELECT timestamp_ns, frame_index, x, y, z, qw, qx, qy, qz, latitude, longitude, jpeg FROM route_frames "
        "WHERE patrol = ?1 ORDER BY position",
        &rows));
    rows.Bind(1, patrol);
    Status status;
    while (rows.Step(&status)) {
      RouteFrame f;
      f.timestamp_ns = rows.Int(0);
      f.frame_index = rows.Int(1);
      if (!rows.IsNull(2)) {
        PoseRecord r{f.timestamp_ns,
                     {rows.Real(2), rows.Real(3), rows.Real(4)},
                     {rows.Real(5), rows.Real(6), rows.Real(7), rows.Real(8)}};
        f.pose = FromRecord(r);
      }
      if (!rows.IsNull(9)) f.gps = Eigen::Vector2d(rows.Real(9), rows.Real(10));
      std::size_t size = 0;
      const unsigned char* jpeg = rows.Blob(11, &size);
      if (jpeg != nullptr) f.jpeg.assign(jpeg, jpeg + size);
      p->route.push_back(std::move(f));
    }
    return status;
  }

  SqliteDatabase* db_;
  const std::string& path_;
  std::vector<std::int64_t> ids_;
};

// The patrol records of `map` in the order flown.
std::vector<const PatrolRecord*> RecordsInFlightOrder(const TopoMap& map) {
  std::vector<const PatrolRecord*> records;
  for (const std::string& flight : map.Flights()) {
    if (const PatrolRecord* record = map.Patrol(flight)) records.push_back(record);
  }
  return records;
}

// The voxels of records[k]'s grid that no later record's grid of the same voxel size holds (each a sorted list).
std::vector<VoxelEvidence> UnseenLater(const std::vector<const PatrolRecord*>& records, std::size_t k) {
  const EvidenceGridData& grid = records[k]->grid;
  std::vector<VoxelEvidence> kept;
  for (const VoxelEvidence& v : grid.voxels) {
    bool seen = false;
    for (std::size_t j = k + 1; j < records.size() && !seen; ++j) {
      const EvidenceGridData& later = records[j]->grid;
      seen = later.voxel_size == grid.voxel_size &&
             std::binary_search(later.voxels.begin(), later.voxels.end(), v, VoxelBefore);
    }
    if (!seen) kept.push_back(v);
  }
  return kept;
}

// Keeps in memory of each record but the last only the voxels no later record observed: the grids then hold the
// site's latest state once (change::LatestState), not every whole patrol the map keeps.
void ThinEarlierGrids(TopoMap* map) {
  const std::vector<const PatrolRecord*> records = RecordsInFlightOrder(*map);
  for (std::size_t k = 0; k + 1 < records.size(); ++k) {
    std::vector<VoxelEvidence> kept = UnseenLater(records, k);
    map->MutablePatrol(records[k]->flight)->grid.voxels = std::move(kept);
  }
}

Status LoadDatabase(const std::string& path, TopoMap* map, PatrolDetail detail) {
  SqliteDatabase db;
  PATROLMAP_RETURN_IF_ERROR(SqliteDatabase::Open(path, SqliteDatabase::Mode::kReadOnly, &db));
  MapReader reader(&db, path);
  *map = TopoMap();
  PATROLMAP_RETURN_IF_ERROR(reader.Info(map));
  PATROLMAP_RETURN_IF_ERROR(reader.Nodes(map));
  PATROLMAP_RETURN_IF_ERROR(reader.Edges(map));
  std::vector<PatrolRecord> records;
  PATROLMAP_RETURN_IF_ERROR(reader.Patrols(&records));
  std::set<std::string> flights;
  for (const PatrolRecord& p : records) {
    // A second record of one flight would replace the first unseen (SetPatrol); a map never holds two.
    if (!flights.insert(p.flight).second) return Corrupt(path, "second patrol record of " + p.flight);
  }
  // kLatest: the route frames of the last flight only (what a new patrol's appearance is compared with).
  const std::vector<std::string> flown = map->Flights();
  const std::string last = flown.empty() ? std::string() : flown.back();
  for (std::size_t i = 0; i < records.size(); ++i) {
    PatrolRecord& p = records[i];
    PATROLMAP_RETURN_IF_ERROR(reader.Grid(i, &p));
    if (detail == PatrolDetail::kAll || p.flight == last) {
      PATROLMAP_RETURN_IF_ERROR(reader.Route(i, &p));
    } else {
      p.partial = true;
    }
    PATROLMAP_RETURN_IF_ERROR(CheckPatrolRecord(path, p));
    map->SetPatrol(std::move(p));
  }
  if (detail == PatrolDetail::kLatest) ThinEarlierGrids(map);
  return Status::Ok();
}

// Which of a route's frames (their times, in order) an archive keeps: the first, then each one at least
// `interval_s` after the last kept; every frame when the interval is 0.
std::vector<bool> ArchiveFramesKept(const std::vector<TimestampNs>& times, double interval_s) {
  std::vector<bool> kept(times.size(), true);
  std::optional<TimestampNs> last;
  for (std::size_t i = 0; i < times.size() && interval_s > 0.0; ++i) {
    if (last && times[i] - *last < SecondsToNs(interval_s)) {
      kept[i] = false;
    } else {
      last = times[i];
    }
  }
  return kept;
}

// records[k] as an archive keeps it: the voxels no later record observed, its archive frames, marked archived.
PatrolRecord ArchivedRecord(const std::vector<const PatrolRecord*>& records, std::size_t k, double interval_s) {
  PatrolRecord archived = *records[k];
  archived.grid.voxels = UnseenLater(records, k);
  std::vector<TimestampNs> times;
  for (const RouteFrame& f : archived.route) times.push_back(f.timestamp_ns);
  const std::vector<bool> kept = ArchiveFramesKept(times, interval_s);
  std::vector<RouteFrame> route;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (kept[i]) route.push_back(std::move(archived.route[i]));
  }
  archived.route = std::move(route);
  archived.archived = true;
  return archived;
}

// Writes `map` whole, each patrol older than the latest `retention.whole_patrols` written as its archive (so a map
// saved whole holds what the same map grown patrol by patrol holds, in the same rows).
Status WriteWhole(const TopoMap& map, const MapRetention& retention, MapWriter* writer) {
  PATROLMAP_RETURN_IF_ERROR(writer->Prepare());
  PATROLMAP_RETURN_IF_ERROR(writer->Info(map));
  for (int i = 0; i < map.node_count(); ++i) PATROLMAP_RETURN_IF_ERROR(writer->Node(i, map.node(i)));
  const std::vector<TopoMap::Edge> edges = map.Edges();
  for (std::size_t i = 0; i < edges.size(); ++i) PATROLMAP_RETURN_IF_ERROR(writer->Edge(static_cast<int>(i), edges[i]));
  const std::vector<const PatrolRecord*> records = RecordsInFlightOrder(map);
  const auto whole = static_cast<std::size_t>(std::max(retention.whole_patrols, 1));
  for (const PatrolRecord& p : map.patrols()) {
    const auto at = std::find(records.begin(), records.end(), &p);
    const auto k = static_cast<std::size_t>(at - records.begin());
    if (at != records.end() && k + whole < records.size()) {
      PATROLMAP_RETURN_IF_ERROR(writer->Patrol(ArchivedRecord(records, k, retention.archive_frame_interval_s)));
    } else {
      PATROLMAP_RETURN_IF_ERROR(writer->Patrol(p));
    }
  }
  return Status::Ok();
}

// What `map` has that the database `db` (the map it was loaded from) does not: nodes and edges after the stored
// ones, and records of flights it has no record of; and the nodes' layout and the objects' site ids, renewed.
// The nodes and edges the database `base` holds, checked to be what `map` was read from (no more of either, and its
// last node the map's): another program may have replaced the file since.
Status StoredCounts(const TopoMap& map, const std::string& base, SqliteDatabase* db, std::int64_t* nodes,
                    std::int64_t* edges) {
  Status status;
  *nodes = Count(db, "SELECT count(*) FROM nodes", &status);
  if (status.ok()) *edges = Count(db, "SELECT count(*) FROM edges", &status);
  PATROLMAP_RETURN_IF_ERROR(status);
  bool same = *nodes <= map.node_count() && *edges <= static_cast<std::int64_t>(map.edge_count());
  if (same && *nodes > 0) {
    const TimestampNs last = map.node(static_cast<int>(*nodes) - 1).timestamp_ns;
    same = Count(db,
                 "SELECT count(*) FROM nodes WHERE id = " + std::to_string(*nodes - 1) +
                     " AND timestamp_ns = " + std::to_string(last),
                 &status) == 1;
    PATROLMAP_RETURN_IF_ERROR(status);
  }
  if (same) return Status::Ok();
  return Status::DataLoss(base + ": changed since this run read it (it holds " + std::to_string(*nodes) +
                          " nodes and " + std::to_string(*edges) + " edges); run again against the map as it is now");
}

Status WriteGrowth(const TopoMap& map, const std::string& base, SqliteDatabase* db, MapWriter* writer) {
  std::int64_t nodes = 0, edges = 0;
  PATROLMAP_RETURN_IF_ERROR(StoredCounts(map, base, db, &nodes, &edges));
  const std::vector<TopoMap::Edge> all_edges = map.Edges();
  PATROLMAP_RETURN_IF_ERROR(writer->Prepare());
  PATROLMAP_RETURN_IF_ERROR(writer->Info(map));
  for (int i = static_cast<int>(nodes); i < map.node_count(); ++i)
    PATROLMAP_RETURN_IF_ERROR(writer->Node(i, map.node(i)));
  for (auto i = static_cast<std::size_t>(edges); i < all_edges.size(); ++i) {
    PATROLMAP_RETURN_IF_ERROR(writer->Edge(static_cast<int>(i), all_edges[i]));
  }
  SqliteStatement layout, site, stored;
  PATROLMAP_RETURN_IF_ERROR(
      db->Prepare("UPDATE nodes SET layout_x = ?1, layout_y = ?2, heading = ?3 WHERE id = ?4", &layout));
  for (int i = 0; i < static_cast<int>(nodes); ++i) {
    const KeyFrameNode& n = map.node(i);
    PATROLMAP_RETURN_IF_ERROR(
        layout.Bind(1, n.layout.x()).Bind(2, n.layout.y()).Bind(3, n.heading).Bind(4, std::int64_t{i}).Run());
  }
  PATROLMAP_RETURN_IF_ERROR(db->Prepare("SELECT id FROM patrols WHERE flight = ?1", &stored));
  PATROLMAP_RETURN_IF_ERROR(
      db->Prepare("UPDATE objects SET site_object = ?1 WHERE patrol = ?2 AND position = ?3", &site));
  Status status;
  for (const PatrolRecord& p : map.patrols()) {
    stored.Bind(1, p.flight);
    const bool has = stored.Step(&status);
    const std::int64_t row = has ? stored.Int(0) : -1;
    stored.Reset();
    PATROLMAP_RETURN_IF_ERROR(status);
    if (!has) {
      if (p.partial) return Corrupt(base, "record of " + p.flight + " is gone from the file it was read from");
      PATROLMAP_RETURN_IF_ERROR(writer->Patrol(p));
      continue;
    }
    for (std::size_t k = 0; k < p.objects.size(); ++k) {
      PATROLMAP_RETURN_IF_ERROR(
          site.Bind(1, std::int64_t{p.objects[k].site_id}).Bind(2, row).Bind(3, static_cast<std::int64_t>(k)).Run());
    }
  }
  return Status::Ok();
}

// Keeps the archive frames of `patrol` (ArchiveFramesKept) in the database.
Status ThinRoute(SqliteDatabase* db, std::int64_t patrol, double interval_s) {
  if (interval_s <= 0.0) return Status::Ok();
  SqliteStatement frames, drop;
  PATROLMAP_RETURN_IF_ERROR(
      db->Prepare("SELECT position, timestamp_ns FROM route_frames WHERE patrol = ?1 ORDER BY position", &frames));
  PATROLMAP_RETURN_IF_ERROR(db->Prepare("DELETE FROM route_frames WHERE patrol = ?1 AND position = ?2", &drop));
  std::vector<std::int64_t> positions;
  std::vector<TimestampNs> times;
  Status status;
  frames.Bind(1, patrol);
  while (frames.Step(&status)) {
    positions.push_back(frames.Int(0));
    times.push_back(frames.Int(1));
  }
  PATROLMAP_RETURN_IF_ERROR(status);
  const std::vector<bool> kept = ArchiveFramesKept(times, interval_s);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (!kept[i]) PATROLMAP_RETURN_IF_ERROR(drop.Bind(1, patrol).Bind(2, positions[i]).Run());
  }
  return Status::Ok();
}

// Archives the patrols older than the latest `retention.whole_patrols` (in the order `map` flew them): each keeps
// of its grid the voxels no later patrol observed (UnseenLater) and is thinned to its archive frames, in the
// database `db` holds `map` in. Each voxel of the site is then stored once, by the latest patrol that observed it.
Status Archive(const TopoMap& map, const MapRetention& retention, SqliteDatabase* db) {
  const std::vector<const PatrolRecord*> records = RecordsInFlightOrder(map);
  const auto whole = static_cast<std::size_t>(std::max(retention.whole_patrols, 1));
  if (records.size() <= whole) return Status::Ok();
  SqliteStatement row, update, mark;
  PATROLMAP_RETURN_IF_ERROR(db->Prepare("SELECT id FROM patrols WHERE flight = ?1", &row));
  PATROLMAP_RETURN_IF_ERROR(db->Prepare("UPDATE grids SET voxels = ?1 WHERE patrol = ?2", &update));
  PATROLMAP_RETURN_IF_ERROR(db->Prepare("UPDATE patrols SET archived = 1 WHERE id = ?1", &mark));
  for (std::size_t k = 0; k + whole < records.size(); ++k) {
    const PatrolRecord& p = *records[k];
    Status status;
    if (!row.Bind(1, p.flight).Step(&status))
      return status.ok() ? Corrupt(db->path(), "no record of " + p.flight) : status;
    const std::int64_t patrol = row.Int(0);
    row.Reset();
    const std::vector<VoxelEvidence> kept = UnseenLater(records, k);
    // An archived record holds in memory what the file holds; a whole one read by a patrol is thinned in memory.
    if (!p.archived || kept.size() != p.grid.voxels.size()) {
      PATROLMAP_RETURN_IF_ERROR(
          update.BindBlob(1, kept.data(), kept.size() * sizeof(VoxelEvidence)).Bind(2, patrol).Run());
    }
    if (!p.archived) {
      PATROLMAP_RETURN_IF_ERROR(ThinRoute(db, patrol, retention.archive_frame_interval_s));
      PATROLMAP_RETURN_IF_ERROR(mark.Bind(1, patrol).Run());
    }
  }
  return Status::Ok();
}
}  // namespace

bool MapRetention::IsValid(std::string* error) const {
  return OptionCheck(error)
      .InRange("map.whole_patrols", whole_patrols, 1, 1000000)
      .InRange("map.archive_frame_interval_s", archive_frame_interval_s, 0.0, 3600.0)
      .ok();
}

Status SaveMap(const TopoMap& map, const std::string& path, const MapRetention& retention) {
  AtomicFile file;
  PATROLMAP_RETURN_IF_ERROR(AtomicFile::Open(path, &file));
  SqliteDatabase db;
  PATROLMAP_RETURN_IF_ERROR(OpenForWriting(file, &db));
  PATROLMAP_RETURN_IF_ERROR(db.Execute(kSchema));
  {
    MapWriter writer(&db);  // its statements finalized before the database closes
    PATROLMAP_RETURN_IF_ERROR(WriteWhole(map, retention, &writer));
  }
  return Finish(&db, &file);
}

Status SaveMapOnto(const TopoMap& map, const std::string& base, const std::string& path,
                   const MapRetention& retention) {
  if (base.empty() || !IsDatabase(base)) return SaveMap(map, path, retention);
  AtomicFile file;
  PATROLMAP_RETURN_IF_ERROR(AtomicFile::Open(path, &file));
  PATROLMAP_RETURN_IF_ERROR(CopyInto(base, &file));
  SqliteDatabase db;
  PATROLMAP_RETURN_IF_ERROR(OpenForWriting(file, &db));
  {
    MapWriter writer(&db);
    PATROLMAP_RETURN_IF_ERROR(WriteGrowth(map, base, &db, &writer));
  }
  PATROLMAP_RETURN_IF_ERROR(Archive(map, retention, &db));
  return Finish(&db, &file);
}

Status LoadMap(const std::string& path, TopoMap* map, PatrolDetail detail) {
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  if (error) return Status::NotFound(path + ": cannot read map: " + error.message());
  const std::string start = FileStart(path, sizeof(kSqliteMagic));
  if (start == std::string(kSqliteMagic, sizeof(kSqliteMagic))) return LoadDatabase(path, map, detail);
  if (start.size() < 8 || std::memcmp(start.data(), kLegacyMagic, 8) != 0) {
    return Status::DataLoss(path + ": not a patrolmap map file");
  }
  std::string bytes(size, '\0');
  std::ifstream(path, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(size));
  return ParseLegacyMap(path, bytes, map);
}

}  // namespace patrolmap::graph
