#include "patrolmap/change/evidence_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <utility>

#include <Eigen/Eigenvalues>

namespace patrolmap::change {
namespace {

bool LexicographicLess(const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

constexpr int kBits = 21;
constexpr std::int64_t kOffset = 1 << 20;
constexpr std::uint64_t kUsed = 1ull << 63;
// The ground around a flat region (IsGroundSheet) is looked for in the columns this far around it [m], as the
// class-agnostic objects look for theirs (GeometryObjectOptions::ground_search_m's default).
constexpr double kGroundRingM = 1.0;
constexpr double kGroundDepthM = 3.0;  // GroundAround looks this far below a box's foot [m]

Eigen::Vector3i UnpackKey(std::uint64_t key) {
  const auto part = [key](int shift) {
    return static_cast<int>(static_cast<std::int64_t>((key >> shift) & ((1ull << kBits) - 1)) - kOffset);
  };
  return {part(2 * kBits), part(kBits), part(0)};
}

double Occupancy(const VoxelEvidence& v) { return static_cast<double>(v.hits) / (v.hits + v.passes); }

struct Region {
  GeometryRegion data;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double score_sum = 0.0;
  std::vector<std::size_t> members;  // indices into the changed voxels
  bool alive = true;
};

bool Overlap(const GeometryRegion& a, const GeometryRegion& b, double tolerance) {
  for (int axis = 0; axis < 3; ++axis) {
    if (a.box_max[axis] + tolerance < b.box_min[axis] || b.box_max[axis] + tolerance < a.box_min[axis]) return false;
  }
  return true;
}

void Absorb(Region* into, Region* from) {
  into->data.voxels += from->data.voxels;
  into->data.appeared += from->data.appeared;
  into->data.vanished += from->data.vanished;
  into->data.box_min = into->data.box_min.cwiseMin(from->data.box_min);
  into->data.box_max = into->data.box_max.cwiseMax(from->data.box_max);
  into->sum += from->sum;
  into->score_sum += from->score_sum;
  into->members.insert(into->members.end(), from->members.begin(), from->members.end());
  into->data.centroid = into->sum / into->data.voxels;
  from->alive = false;
}

// Paper 004's aggregation: nearest region centroid within the join distance, else a new region.
std::vector<Region> Cluster(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& changes,
                            double join_distance) {
  std::vector<Region> regions;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    Region* best = nullptr;
    double best_distance = join_distance;
    for (Region& region : regions) {
      const double distance = (region.data.centroid - centres[i]).norm();
      if (distance <= best_distance) best = &region, best_distance = distance;
    }
    if (best == nullptr) {
      regions.emplace_back();
      best = &regions.back();
      best->data.box_min = best->data.box_max = centres[i];
    }
    Region single;
    single.data.voxels = 1;
    (changes[i] > 0 ? single.data.appeared : single.data.vanished) = 1;
    single.data.box_min = single.data.box_max = centres[i];
    single.sum = centres[i];
    single.score_sum = std::abs(changes[i]);
    single.members = {i};
    Absorb(best, &single);
  }
  return regions;
}

// Cleanup: while two regions overlap, the smaller joins the larger.
void MergeOverlapping(double tolerance, std::vector<Region>* regions) {
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t a = 0; a < regions->size(); ++a) {
      for (std::size_t b = a + 1; b < regions->size(); ++b) {
        Region& ra = (*regions)[a];
        Region& rb = (*regions)[b];
        if (!ra.alive || !rb.alive || !Overlap(ra.data, rb.data, tolerance)) continue;
        if (ra.data.voxels >= rb.data.voxels)
          Absorb(&ra, &rb);
        else
          Absorb(&rb, &ra);
        merged = true;
      }
    }
  }
}

}  // namespace

bool IsOccupied(const VoxelEvidence* voxel) {
  return voxel != nullptr && voxel->hits >= 2 && voxel->hits > voxel->passes;
}

std::uint64_t VoxelKey(const Eigen::Vector3i& v) {
  const auto part = [](int value) { return static_cast<std::uint64_t>(value + kOffset) & ((1ull << kBits) - 1); };
  return kUsed | part(v.x()) << (2 * kBits) | part(v.y()) << kBits | part(v.z());
}

VoxelLookup LookupIn(const EvidenceGridData& grid) {
  return [&grid](const Eigen::Vector3i& index, VoxelEvidence* voxel) {
    const VoxelEvidence* found = FindVoxel(grid, index);
    if (found != nullptr) *voxel = *found;
    return found != nullptr;
  };
}

VoxelLookup LookupIn(const EvidenceGrid& grid, const Eigen::Vector3i& shift) {
  if (shift == Eigen::Vector3i::Zero()) {
    return [&grid](const Eigen::Vector3i& index, VoxelEvidence* voxel) { return grid.Lookup(index, voxel); };
  }
  return [&grid, shift](const Eigen::Vector3i& index, VoxelEvidence* voxel) {
    if (!grid.Lookup(index - shift, voxel)) return false;
    voxel->x += shift.x(), voxel->y += shift.y(), voxel->z += shift.z();
    return true;
  };
}

Eigen::Vector3i VoxelIndex(const Eigen::Vector3d& point, double voxel_size) {
  return (point / voxel_size).array().round().cast<int>();
}

const VoxelEvidence* FindVoxel(const EvidenceGridData& grid, const Eigen::Vector3i& index) {
  const VoxelEvidence key{index.x(), index.y(), index.z(), 0, 0};
  const auto it = std::lower_bound(grid.voxels.begin(), grid.voxels.end(), key, VoxelBefore);
  if (it == grid.voxels.end() || VoxelBefore(key, *it)) return nullptr;
  return &*it;
}

std::size_t EvidenceGrid::MaxVoxels(const EvidenceGridOptions& options) {
  const double bytes = options.memory_mb * 1024.0 * 1024.0;
  std::size_t slots = 2;
  while (2.0 * static_cast<double>(2 * slots * sizeof(Slot)) <= bytes) slots *= 2;  // room for a copy
  return slots / 2;
}

EvidenceGrid::EvidenceGrid(const EvidenceGridOptions& options)
    : options_(options), max_voxels_(MaxVoxels(options)), slots_(std::min<std::size_t>(1 << 16, 2 * max_voxels_)) {}

EvidenceGrid::Slot* EvidenceGrid::Find(std::uint64_t key) {
  const int bits = __builtin_ctzll(slots_.size());
  std::size_t i = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bits));
  const std::size_t mask = slots_.size() - 1;
  while (true) {
    Slot& slot = slots_[i];
    if (slot.key == key) return &slot;
    if (slot.key == 0) {
      if (size_ >= max_voxels_) return Evict() ? Find(key) : nullptr;
      // Grow at three quarters full: each growth holds the old table and the new, twice its size, at once
      // (a memory peak), so it comes late. The largest table (2 * max_voxels_ slots) is never more than half
      // full.
      if (4 * (size_ + 1) > 3 * slots_.size()) {
        Grow();
        return Find(key);
      }
      slot.key = key;
      ++size_;
      return &slot;
    }
    i = (i + 1) & mask;
  }
}

const EvidenceGrid::Slot* EvidenceGrid::Probe(std::uint64_t key) const {
  const int bits = __builtin_ctzll(slots_.size());
  std::size_t i = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bits));
  const std::size_t mask = slots_.size() - 1;
  while (slots_[i].key != 0) {
    if (slots_[i].key == key) return &slots_[i];
    i = (i + 1) & mask;
  }
  return nullptr;
}

bool EvidenceGrid::Lookup(const Eigen::Vector3i& index, VoxelEvidence* voxel) const {
  const Slot* slot = Probe(VoxelKey(index));
  if (slot == nullptr) return false;
  *voxel = {index.x(), index.y(), index.z(), slot->hits, slot->passes};
  return true;
}

std::vector<Eigen::Vector3i> EvidenceGrid::OccupiedVoxels() const {
  std::vector<Eigen::Vector3i> occupied;
  for (const Slot& slot : slots_) {
    const VoxelEvidence counts{0, 0, 0, slot.hits, slot.passes};
    if (slot.key != 0 && IsOccupied(&counts)) occupied.push_back(UnpackKey(slot.key));
  }
  return occupied;
}

// Puts a slot's key into the (not full) table; its counts are the caller's to copy.
EvidenceGrid::Slot* EvidenceGrid::Insert(std::uint64_t key) {
  const int bits = __builtin_ctzll(slots_.size());
  std::size_t i = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bits));
  const std::size_t mask = slots_.size() - 1;
  while (slots_[i].key != 0) i = (i + 1) & mask;
  slots_[i].key = key;
  ++size_;
  return &slots_[i];
}

void EvidenceGrid::Grow() {
  std::vector<Slot> old(slots_.size() * 2);
  old.swap(slots_);
  size_ = 0;
  for (const Slot& slot : old) {
    if (slot.key != 0) *Insert(slot.key) = slot;
  }
}

// Drops the least recently observed quarter of the voxels (those last reached by the oldest depth images),
// never one the current image reached. False when there is none to drop.
bool EvidenceGrid::Evict() {
  std::vector<std::uint32_t> stamps;
  for (const Slot& slot : slots_) {
    if (slot.key != 0 && slot.stamp < stamp_) stamps.push_back(slot.stamp);
  }
  if (stamps.empty()) return false;
  const std::size_t count = std::min(stamps.size(), std::max<std::size_t>(1, size_ / 4));
  std::nth_element(stamps.begin(), stamps.begin() + (count - 1), stamps.end());
  const std::uint32_t oldest_kept = stamps[count - 1] + 1;
  stamps = std::vector<std::uint32_t>();
  std::vector<Slot> old(slots_.size());
  old.swap(slots_);
  size_ = 0;
  for (const Slot& slot : old) {
    if (slot.key == 0) continue;
    if (slot.stamp < oldest_kept) {
      ++evicted_;
      continue;
    }
    *Insert(slot.key) = slot;
  }
  return true;
}

void EvidenceGrid::TraceRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& end, bool hit, double hold_back_m) {
  const Eigen::Vector3d a = origin / options_.voxel_size_m + Eigen::Vector3d::Constant(0.5);
  const Eigen::Vector3d b = end / options_.voxel_size_m + Eigen::Vector3d::Constant(0.5);
  Eigen::Vector3i voxel = a.array().floor().cast<int>();
  const Eigen::Vector3i last = b.array().floor().cast<int>();
  const Eigen::Vector3d d = b - a;
  int step[3];
  double t_max[3], t_delta[3];
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    step[axis] = d[axis] > 0 ? 1 : (d[axis] < 0 ? -1 : 0);
    if (step[axis] == 0) {
      t_max[axis] = t_delta[axis] = kInf;
      continue;
    }
    const double boundary = voxel[axis] + (step[axis] > 0 ? 1.0 : 0.0);
    t_max[axis] = (boundary - a[axis]) / d[axis];
    t_delta[axis] = std::abs(1.0 / d[axis]);
  }
  int remaining = (last - voxel).cwiseAbs().sum();
  // Voxels entered after t_free (of the way from origin to end) lie within the return's uncertainty: not free.
  const double length = (end - origin).norm();
  const double t_free = length > 0.0 ? 1.0 - hold_back_m / length : 1.0;
  double t_entry = 0.0;
  const auto count = [this](const Eigen::Vector3i& v, bool is_hit) {
    Slot* slot = Find(VoxelKey(v));
    if (slot == nullptr) return void(++dropped_);
    std::uint16_t& counter = is_hit ? slot->hits : slot->passes;
    if (counter < std::numeric_limits<std::uint16_t>::max()) ++counter;
    slot->stamp = stamp_;
  };
  while (remaining-- > 0) {
    if (t_entry < t_free) count(voxel, false);
    const int axis = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    voxel[axis] += step[axis];
    t_entry = t_max[axis];
    t_max[axis] += t_delta[axis];
  }
  count(last, hit);
}

int EvidenceGrid::RayStep(int cols) const {
  return std::max(1, static_cast<int>(std::lround(static_cast<double>(cols) / options_.rays_per_row)));
}

void EvidenceGrid::Integrate(const cv::Mat& depth_m, const CameraIntrinsics& camera, const CameraPoseSample& pose,
                             double range_sigma_per_m2, const cv::Mat& error_scale) {
  constexpr double kNoReturnBeyond = 65.0;  // 16-bit millimetre depth saturates at 65.535 m
  ++stamp_;
  const int step = RayStep(depth_m.cols);
  for (int y = step / 2; y < depth_m.rows; y += step) {
    const float* row = depth_m.ptr<float>(y);
    const float* fused = error_scale.empty() ? nullptr : error_scale.ptr<float>(y);
    for (int x = step / 2; x < depth_m.cols; x += step) {
      const double depth = row[x];
      if (depth <= 0.0) continue;  // no return: unknown
      const Eigen::Vector3d ray((x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy, 1.0);
      const double length = depth * ray.norm();
      const bool hit = depth < kNoReturnBeyond && length <= options_.max_range_m;
      const double traced = hit ? depth : options_.max_range_m / ray.norm();
      // Free space ends free_space_sigmas range errors before a return (the error grows with depth squared).
      double sigma = range_sigma_per_m2 * length * length;
      if (fused != nullptr && fused[x] > 0.0f) sigma *= fused[x];
      // A return too uncertain to place in a voxel still says the space before it is free.
      const double hold_back = hit ? options_.free_space_sigmas * sigma : 0.0;
      TraceRay(pose.position, pose.ToWorld(traced * ray), hit && sigma <= options_.max_hit_sigma_m, hold_back);
    }
  }
}

EvidenceGridData EvidenceGrid::ToData() const {
  EvidenceGridData data;
  data.voxel_size = options_.voxel_size_m;
  data.evicted_voxels = evicted_;
  data.voxels.reserve(size_);
  for (const Slot& slot : slots_) {
    if (slot.key == 0) continue;
    const Eigen::Vector3i v = UnpackKey(slot.key);
    data.voxels.push_back({v.x(), v.y(), v.z(), slot.hits, slot.passes});
  }
  std::sort(data.voxels.begin(), data.voxels.end(), VoxelBefore);
  return data;
}

EvidenceGridData EvidenceGrid::TakeData() {
  EvidenceGridData data = ToData();
  std::vector<Slot>(std::min<std::size_t>(1 << 16, 2 * max_voxels_)).swap(slots_);  // as a new grid's
  size_ = 0;
  return data;
}

namespace {

// True when a voxel next to `index` is occupied in the grid `find` reads (find(index, &voxel) -> bool), the
// patrol where `index` is free: the same surface seen a voxel off (an edge or a corner from a slightly different
// view) explains the change. With `vertical` false only the horizontal neighbours count.
template <typename FindVoxelIn>
bool OccupiedNeighbour(const FindVoxelIn& find, const Eigen::Vector3i& index, int reach, bool vertical) {
  VoxelEvidence voxel;
  for (int dz = vertical ? -reach : 0; dz <= (vertical ? reach : 0); ++dz) {
    for (int dy = -reach; dy <= reach; ++dy) {
      for (int dx = -reach; dx <= reach; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        if (find(index + Eigen::Vector3i(dx, dy, dz), &voxel) && IsOccupied(&voxel)) return true;
      }
    }
  }
  return false;
}

// Whether a region one voxel layer thick (voxel-centre box `low`-`high`) lies on the ground: the ground around it
// (GroundAround over both patrols' grids, searched up to one voxel above the region) is at most one voxel below it.
// Such a region is the ground seen a voxel higher or lower (what correcting GPS poses to the nearest whole voxel
// leaves); a new roof or a lid seen from above has the ground around it lower.
template <typename FindBefore, typename FindAfter>
bool IsGroundSheet(const Eigen::Vector3i& low, const Eigen::Vector3i& high, const FindBefore& find_before,
                   const FindAfter& find_after, double voxel) {
  const VoxelLookup either = [&](const Eigen::Vector3i& index, VoxelEvidence* evidence) {
    return (find_before(index, evidence) && evidence->hits > 0) || (find_after(index, evidence) && evidence->hits > 0);
  };
  const std::optional<int> ground = GroundAround(low, high, voxel, kGroundRingM, 1, either);
  return ground && *ground >= low.z() - 1;
}

// The columns of `members` (of `changed`) in which a voxel occupied in both patrols (`find_before`, `find_after`)
// stands at most `reach` voxels above a member.
template <typename FindBefore, typename FindAfter>
int CappedColumns(const std::vector<std::size_t>& members, const std::vector<Eigen::Vector3i>& changed,
                  const FindBefore& find_before, const FindAfter& find_after, int reach) {
  std::set<std::pair<int, int>> capped;
  VoxelEvidence before, after;
  for (std::size_t m : members) {
    const Eigen::Vector3i& v = changed[m];
    for (int dz = 1; dz <= reach && capped.count({v.x(), v.y()}) == 0; ++dz) {
      const Eigen::Vector3i above = v + Eigen::Vector3i(0, 0, dz);
      if (find_before(above, &before) && IsOccupied(&before) && find_after(above, &after) && IsOccupied(&after)) {
        capped.insert({v.x(), v.y()});
      }
    }
  }
  return static_cast<int>(capped.size());
}

// How thin a region's changed voxels are seen from above: their spread across the horizontal direction they spread
// along most (standard deviation, in voxels; 0 for voxels in one vertical plane).
double Thickness(const std::vector<std::size_t>& members, const std::vector<Eigen::Vector3i>& changed) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t m : members) mean += changed[m].head<2>().cast<double>();
  mean /= static_cast<double>(members.size());
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (std::size_t m : members) {
    const Eigen::Vector2d d = changed[m].head<2>().cast<double>() - mean;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(members.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance);
  return std::sqrt(std::max(0.0, solver.eigenvalues()(0)));  // the smaller, first
}

// DiffGrids over `before` and a grid read through `find_after` (as OccupiedNeighbour) whose common voxels
// `for_each_common` visits in `before`'s order.
template <typename FindAfter, typename ForEachCommon>
void DiffVoxels(const EvidenceGridData& before, const FindAfter& find_after, const ForEachCommon& for_each_common,
                const GeometryDiffOptions& options, GeometryChange* change) {
  const double size = before.voxel_size;
  change->voxel_size = size;
  change->evicted_prior = before.evicted_voxels;
  const VoxelLookup find_before = LookupIn(before);
  std::vector<Eigen::Vector3i> changed;
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> deltas;
  std::vector<Eigen::Vector3i>& cells = change->compared_cells;
  const auto observed = [&options](const VoxelEvidence& v) { return v.hits + v.passes >= options.min_observations; };
  for_each_common([&](const VoxelEvidence& a, const VoxelEvidence& b) {
    if (!observed(a) || !observed(b)) return;
    ++change->compared_voxels;
    const Eigen::Vector3i cell =
        (Eigen::Vector3d(a.x, a.y, a.z) * (size / GeometryChange::kComparedCellM)).array().floor().cast<int>();
    if (cells.empty() || cells.back() != cell) cells.push_back(cell);
    const double delta = Occupancy(b) - Occupancy(a);
    const bool one_free = std::min(Occupancy(a), Occupancy(b)) <= options.max_free_occupancy;
    // A surface voxel: occupied in one patrol at least; a changed voxel counts as one, so the differing share
    // stays within 1.
    const bool surface =
        std::max(Occupancy(a), Occupancy(b)) > options.max_free_occupancy + options.min_occupancy_change;
    if (surface) ++change->surface_voxels;
    const Eigen::Vector3i index(a.x, a.y, a.z);
    if (std::abs(delta) <= options.min_occupancy_change || !one_free) return;
    const VoxelEvidence &free = delta > 0 ? a : b, &occupied = delta > 0 ? b : a;
    if (free.hits + free.passes < options.min_free_ratio * occupied.hits) return;
    if (options.surface_tolerance_voxels > 0) {
      const bool explained =
          delta > 0
              ? OccupiedNeighbour(find_before, index, options.surface_tolerance_voxels, options.vertical_tolerance)
              : OccupiedNeighbour(find_after, index, options.surface_tolerance_voxels, options.vertical_tolerance);
      if (explained) return;
    }
    if (!surface) ++change->surface_voxels;
    changed.push_back(index);
    centres.push_back(index.cast<double>() * size);
    deltas.push_back(delta);
  });
  std::sort(cells.begin(), cells.end(), LexicographicLess);
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  change->differing_voxels = static_cast<long long>(changed.size());
  if (change->DifferingShare() > options.max_differing_share) {
    change->poses_disagree = true;  // surfaces a voxel or more apart everywhere: not changes, a pose error
    return;
  }
  std::vector<Region> regions = Cluster(centres, deltas, options.join_distance_m);
  MergeOverlapping(size * 1.01, &regions);  // voxel cubes that touch or overlap
  std::vector<std::size_t> members;         // the changed voxels of the reported regions
  for (Region& region : regions) {
    if (!region.alive || region.data.voxels < options.min_region_voxels) continue;
    const Eigen::Vector3d extent = region.data.box_max - region.data.box_min + Eigen::Vector3d::Constant(size);
    if (std::max(extent.x(), extent.y()) < options.min_region_width_m - 1e-9) continue;
    if (region.data.appeared > 0 && region.data.vanished > 0 &&
        Thickness(region.members, changed) < options.min_shift_thickness_voxels) {
      continue;  // an edge seen a voxel off
    }
    if (options.min_capped_columns > 0 && (region.data.appeared == 0 || region.data.vanished == 0) &&
        CappedColumns(region.members, changed, find_before, find_after, options.cap_search_voxels) >=
            options.min_capped_columns) {
      continue;  // the top of a thing still there: its lower part seen through
    }
    if (options.drop_ground_sheets && extent.z() < 1.5 * size) {
      const Eigen::Vector3i low = (region.data.box_min / size).array().round().cast<int>();
      const Eigen::Vector3i high = (region.data.box_max / size).array().round().cast<int>();
      if (IsGroundSheet(low, high, find_before, find_after, size)) continue;
    }
    region.data.score = region.score_sum / region.data.voxels;
    change->regions.push_back(region.data);
    members.insert(members.end(), region.members.begin(), region.members.end());
  }
  std::stable_sort(change->regions.begin(), change->regions.end(),
                   [](const GeometryRegion& x, const GeometryRegion& y) { return x.voxels > y.voxels; });
  std::sort(members.begin(), members.end(),
            [&changed](std::size_t x, std::size_t y) { return LexicographicLess(changed[x], changed[y]); });
  for (std::size_t member : members) {
    change->changed_voxels.push_back(changed[member]);
    change->changed_deltas.push_back(static_cast<float>(deltas[member]));
  }
}

}  // namespace

bool GeometryChange::ComparedNear(const Eigen::Vector3d& point) const {
  const Eigen::Vector3i at = (point / kComparedCellM).array().floor().cast<int>();
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        if (std::binary_search(compared_cells.begin(), compared_cells.end(), at + Eigen::Vector3i(dx, dy, dz),
                               LexicographicLess)) {
          return true;
        }
      }
  return false;
}

std::optional<int> GroundAround(const Eigen::Vector3i& low, const Eigen::Vector3i& high, double voxel, double ring_m,
                                int above, const VoxelLookup& grid) {
  const int reach = static_cast<int>(std::ceil(ring_m / voxel));
  const int below = static_cast<int>(std::ceil(kGroundDepthM / voxel));
  std::vector<int> lowest;
  VoxelEvidence evidence;
  for (int y = low.y() - reach; y <= high.y() + reach; ++y) {
    for (int x = low.x() - reach; x <= high.x() + reach; ++x) {
      if (x >= low.x() && x <= high.x() && y >= low.y() && y <= high.y()) continue;  // under the box
      for (int z = low.z() - below; z <= low.z() + above; ++z) {
        // Any return: the ground seen at a grazing angle has more rays passing its voxel than ending in it.
        if (grid(Eigen::Vector3i(x, y, z), &evidence) && evidence.hits > 0) {
          lowest.push_back(z);
          break;
        }
      }
    }
  }
  if (lowest.empty()) return std::nullopt;
  std::nth_element(lowest.begin(), lowest.begin() + lowest.size() / 2, lowest.end());
  return lowest[lowest.size() / 2];
}

bool PosesHaveZUp(const std::string& prior_source, const std::string& current_source) {
  return prior_source == kPosesFromGps || current_source == kPosesFromGps;
}

bool ZPointsUp(const std::string& prior_source, const std::string& current_source) {
  return prior_source != kPosesFromFile && current_source != kPosesFromFile;
}

GeometryDiffOptions ForPoseSources(GeometryDiffOptions options, const std::string& prior_source,
                                   const std::string& current_source) {
  options.drop_ground_sheets &= PosesHaveZUp(prior_source, current_source);
  if (!ZPointsUp(prior_source, current_source)) {
    options.min_capped_columns = 0;
  }
  return options;
}

GeometryObjectOptions ForPoseSources(GeometryObjectOptions options, const std::string& prior_source,
                                     const std::string& current_source) {
  options.drop_ground_sheets &= PosesHaveZUp(prior_source, current_source);
  return options;
}

bool DiffGrids(const EvidenceGridData& before, const EvidenceGridData& after, const GeometryDiffOptions& options,
               GeometryChange* change) {
  *change = GeometryChange();
  if (before.voxel_size <= 0.0 || before.voxel_size != after.voxel_size) return false;
  change->evicted_current = after.evicted_voxels;
  const VoxelLookup find_after = LookupIn(after);
  const auto for_each_common = [&](const auto& visit) { ForEachCommonVoxel(before, after, visit); };
  DiffVoxels(before, find_after, for_each_common, options, change);
  return true;
}

bool DiffGrids(const EvidenceGridData& before, const EvidenceGrid& after, const GeometryDiffOptions& options,
               GeometryChange* change, const Eigen::Vector3i& after_shift) {
  *change = GeometryChange();
  if (before.voxel_size <= 0.0 || before.voxel_size != after.voxel_size()) return false;
  change->evicted_current = after.evicted_voxels();
  const VoxelLookup find_after = LookupIn(after, after_shift);
  // The prior's voxels in their (sorted) order, each looked up in the live grid: the merge's order.
  const auto for_each_common = [&](const auto& visit) {
    VoxelEvidence current;
    for (const VoxelEvidence& prior : before.voxels) {
      if (after.Lookup(Eigen::Vector3i(prior.x, prior.y, prior.z) - after_shift, &current)) visit(prior, current);
    }
  };
  DiffVoxels(before, find_after, for_each_common, options, change);
  return true;
}

}  // namespace patrolmap::change
