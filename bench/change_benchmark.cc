// Change-stage speed on rendered village views at 376x240 (the processing
// size of a 752x480 camera): object association per detection (paper 000
// needed 15 ms per object), evidence-grid integration per depth frame, the
// grid comparison of two patrols, the class-agnostic objects from it, the object comparison of two long patrols, the
// appearance comparison of one place, and
// appearance along the route (features per route frame, registration per candidate, comparison per pair, a whole
// route).
#include <array>

#include <benchmark/benchmark.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/change/appearance.h"
#include "patrolmap/change/evidence_grid.h"
#include "patrolmap/change/geometry_objects.h"
#include "patrolmap/change/object_diff.h"
#include "patrolmap/change/object_map.h"
#include "patrolmap/change/route_compare.h"
#include "patrolmap/change/route_depth.h"
#include "patrolmap/depth/lens.h"
#include "patrolmap/sim/objects.h"
#include "patrolmap/sim/renderer.h"
#include "patrolmap/sim/village.h"

namespace {

using namespace patrolmap;

const CameraIntrinsics kCamera{229.0, 229.0, 187.5, 119.5, 376, 240};

// A village with 30 objects and a camera on the south street looking north at them.
struct View {
  sim::Scene scene;
  std::vector<sim::WorldObject> objects;
  sim::CameraPose pose;
  CameraPoseSample sample;
  cv::Mat image, depth_m;
  std::vector<ObjectObservation> detections;
};

CameraPoseSample ToSample(const sim::CameraPose& pose) {
  return {0, pose.position, Eigen::Quaterniond(sim::WorldFromCameraRotation(pose.yaw))};
}

View Render(double x, const std::vector<sim::WorldObject>& objects, const sim::Lighting& lighting) {
  View view;
  view.scene = sim::MakeVillage({1}).scene;
  view.objects = objects;
  sim::AddObjects(objects, &view.scene);
  view.pose = {Eigen::Vector3d(x, -7.0, 3.0), M_PI / 2};
  view.sample = ToSample(view.pose);
  sim::Renderer renderer(&view.scene, kCamera, lighting);
  renderer.Render(view.pose, &view.image);
  cv::Mat depth_mm;
  renderer.RenderDepth(view.pose, &depth_mm);
  depth_mm.convertTo(view.depth_m, CV_32FC1, 1e-3);
  sim::DetectorOptions detector;
  detector.miss_rate = detector.false_rate = 0.0;
  for (const sim::Detection& d : sim::DetectObjects(objects, view.scene, kCamera, view.pose, detector, 1)) {
    view.detections.push_back({0, sim::ToString(d.label), d.confidence, d.box, d.centroid});
  }
  return view;
}

// Index of the object on the south street nearest to x = 20 m.
std::size_t SouthObject(const std::vector<sim::WorldObject>& objects) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].centre.y() < 0.0 &&
        (objects[best].centre.y() >= 0.0 ||
         std::abs(objects[i].centre.x() - 20) < std::abs(objects[best].centre.x() - 20))) {
      best = i;
    }
  }
  return best;
}

const View& Village() {
  static const View view = Render(20.0, sim::PlaceObjects(30, 1), {});
  return view;
}

void BM_ObjectAssociationPerDetection(benchmark::State& state) {
  const View& view = Village();
  change::ObjectMapper mapper(change::ObjectMapOptions{}, kCamera);
  for (int i = 0; i < 5; ++i) mapper.AddFrame(view.detections, view.sample, view.depth_m, view.image);
  const int before = mapper.associations();
  const double seconds_before = mapper.association_seconds();
  for (auto _ : state) mapper.AddFrame(view.detections, view.sample, view.depth_m, view.image);
  const int associations = mapper.associations() - before;
  state.counters["detections_per_frame"] = static_cast<double>(view.detections.size());
  state.counters["association_ms"] = 1e3 * (mapper.association_seconds() - seconds_before) / std::max(1, associations);
  state.SetItemsProcessed(associations);
}
BENCHMARK(BM_ObjectAssociationPerDetection)->Unit(benchmark::kMillisecond);

void BM_EvidenceGridIntegrateFrame(benchmark::State& state) {
  const View& view = Village();
  change::EvidenceGrid grid(change::EvidenceGridOptions{});
  for (auto _ : state) grid.Integrate(view.depth_m, kCamera, view.sample);
  state.counters["voxels"] = static_cast<double>(grid.voxel_count());
}
BENCHMARK(BM_EvidenceGridIntegrateFrame)->Unit(benchmark::kMillisecond);

// Two grids along 40 m of street (a depth frame every 0.26 m, as at 5 Hz and 1.3 m/s), one with an object removed.
const std::array<EvidenceGridData, 2>& FortyMetreGrids() {
  static const std::array<EvidenceGridData, 2> grids = [] {
    std::vector<sim::WorldObject> objects = sim::PlaceObjects(30, 1);
    std::vector<sim::WorldObject> fewer = objects;
    fewer.erase(fewer.begin() + static_cast<std::ptrdiff_t>(SouthObject(objects)));
    std::array<EvidenceGridData, 2> built;
    for (int g = 0; g < 2; ++g) {
      change::EvidenceGrid grid(change::EvidenceGridOptions{});
      for (double x = 0.0; x < 40.0; x += 0.26) {
        const View view = Render(x, g == 0 ? objects : fewer, {});
        grid.Integrate(view.depth_m, kCamera, view.sample);
      }
      built[g] = grid.ToData();
    }
    return built;
  }();
  return grids;
}

void BM_DiffGridsFortyMetres(benchmark::State& state) {
  const std::array<EvidenceGridData, 2>& grids = FortyMetreGrids();
  change::GeometryChange change;
  for (auto _ : state) change::DiffGrids(grids[0], grids[1], change::GeometryDiffOptions{}, &change);
  state.counters["voxels"] = static_cast<double>(grids[0].voxels.size());
  state.counters["regions"] = static_cast<double>(change.regions.size());
}
BENCHMARK(BM_DiffGridsFortyMetres)->Unit(benchmark::kMillisecond);

// Class-agnostic objects from the changed voxels of those grids: clusters, each completed in its patrol's grid.
void BM_GeometryObjectsFortyMetres(benchmark::State& state) {
  const std::array<EvidenceGridData, 2>& grids = FortyMetreGrids();
  change::GeometryChange change;
  change::DiffGrids(grids[0], grids[1], change::GeometryDiffOptions{}, &change);
  const change::VoxelLookup prior = change::LookupIn(grids[0]), current = change::LookupIn(grids[1]);
  std::vector<change::ObjectChange> objects;
  for (auto _ : state)
    objects = change::GeometryObjects(change, prior, current, {}, {}, change::GeometryObjectOptions{});
  state.counters["changed_voxels"] = static_cast<double>(change.changed_voxels.size());
  state.counters["objects"] = static_cast<double>(objects.size());
}
BENCHMARK(BM_GeometryObjectsFortyMetres)->Unit(benchmark::kMillisecond);

// Two patrols of a 1 km street with range(0) objects along it, 2 m apart on both sides, and a view each metre
// looking along the street; every third object is gone or moved by 3 m in the second patrol.
PatrolRecord StreetPatrol(int objects, bool second) {
  PatrolRecord record;
  record.camera = kCamera;
  record.has_objects = true;
  const double length = objects;  // [m]: one object a metre, alternately on either side
  for (double x = 0.0; x <= length; x += 1.0) {
    record.views.push_back({0, Eigen::Vector3d(x, 0.0, 3.0), Eigen::Quaterniond(sim::WorldFromCameraRotation(0.0))});
  }
  for (int i = 0; i < objects; ++i) {
    if (second && i % 3 == 1) continue;  // removed
    MapObject o;
    o.id = i;
    o.label = i % 2 == 0 ? "crate" : "vehicle";
    o.confidence = 0.8;
    o.detections = 10;
    o.centroid = Eigen::Vector3d(i, i % 2 == 0 ? 6.0 : -6.0, 0.5);
    if (second && i % 3 == 2) o.centroid.x() += 3.0;  // moved
    o.box_min = o.centroid - Eigen::Vector3d::Constant(0.5);
    o.box_max = o.centroid + Eigen::Vector3d::Constant(0.5);
    record.objects.push_back(o);
  }
  return record;
}

void BM_DiffObjectsLongPatrol(benchmark::State& state) {
  const PatrolRecord prior = StreetPatrol(static_cast<int>(state.range(0)), false);
  const PatrolRecord current = StreetPatrol(static_cast<int>(state.range(0)), true);
  for (auto _ : state) benchmark::DoNotOptimize(change::DiffObjects(prior, current, change::ObjectDiffOptions{}));
  state.counters["views"] = static_cast<double>(prior.views.size());
}
BENCHMARK(BM_DiffObjectsLongPatrol)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond);

// The move test of one vanished and one appeared cluster: the surfaces of a 4.4 x 1.8 x 1.6 m vehicle (0.2 m voxels,
// about 1,000 each) 2 m apart, registered centroid onto centroid (argument 0) or at the best shift of up to 0.6 m
// each way (argument 1: change.geometry_objects.shape_search_m, 49 shifts).
void BM_GeometryObjectsMovedVehicle(benchmark::State& state) {
  const auto surface = [](int x0) {
    std::vector<Eigen::Vector3i> voxels;
    for (int x = 0; x < 22; ++x) {
      for (int y = 0; y < 9; ++y) {
        for (int z = 0; z < 8; ++z) {
          if (x == 0 || y == 0 || z == 0 || x == 21 || y == 8 || z == 7) voxels.emplace_back(x0 + x, y, z);
        }
      }
    }
    return voxels;
  };
  change::GeometryChange change;
  change.voxel_size = 0.2;
  for (const Eigen::Vector3i& v : surface(0))
    change.changed_voxels.push_back(v), change.changed_deltas.push_back(-0.9f);
  for (const Eigen::Vector3i& v : surface(32))
    change.changed_voxels.push_back(v), change.changed_deltas.push_back(0.9f);
  change::GeometryObjectOptions options;
  options.complete_objects = false;
  options.shape_search_m = state.range(0) == 0 ? 0.0 : 0.6;
  std::vector<change::ObjectChange> objects;
  for (auto _ : state) objects = change::GeometryObjects(change, {}, {}, {}, {}, options);
  state.counters["voxels"] = static_cast<double>(change.changed_voxels.size());
  state.counters["moved"] = static_cast<double>(objects.size() == 1 && objects[0].state == change::ObjectState::kMoved);
}
BENCHMARK(BM_GeometryObjectsMovedVehicle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

change::KeyFrameView Describe(const cv::Mat& image) {
  change::KeyFrameView view;
  cv::Mat thumbnail;
  cv::resize(image, thumbnail, cv::Size(160, 102), 0, 0, cv::INTER_AREA);
  view.image = thumbnail;
  view.feature_scale = static_cast<double>(image.cols) / thumbnail.cols;
  std::vector<cv::KeyPoint> keypoints;
  cv::SIFT::create(800)->detectAndCompute(image, cv::noArray(), keypoints, view.descriptors);
  cv::KeyPoint::convert(keypoints, view.points);
  return view;
}

void BM_AppearanceChangePerPlace(benchmark::State& state) {
  std::vector<sim::WorldObject> objects = sim::PlaceObjects(30, 1);
  const std::size_t removed = SouthObject(objects);
  const double x = objects[removed].centre.x();
  const change::KeyFrameView prior = Describe(Render(x, objects, sim::DrawLighting(1, 1)).image);
  objects.erase(objects.begin() + static_cast<std::ptrdiff_t>(removed));
  const change::KeyFrameView current = Describe(Render(x + 0.3, objects, sim::DrawLighting(1, 2)).image);
  state.counters["object_x"] = x;
  change::AppearanceChange change;
  for (auto _ : state) change = change::DetectAppearanceChange(prior, current, change::AppearanceOptions{});
  state.counters["inliers"] = change.inliers;
  state.counters["regions"] = static_cast<double>(change.regions.size());
}
BENCHMARK(BM_AppearanceChangePerPlace)->Unit(benchmark::kMillisecond);

// Appearance along the route (route_compare.h): a route frame at 376x240 as the map keeps it (JPEG).
RouteFrame RouteFrameAt(double x, const std::vector<sim::WorldObject>& objects, const sim::Lighting& lighting,
                        double seconds) {
  RouteFrame frame;
  frame.timestamp_ns = SecondsToNs(seconds);
  const View view = Render(x, objects, lighting);
  cv::imencode(".jpg", view.image, frame.jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
  frame.pose = view.sample;
  return frame;
}

// EuRoC cam0's lens (k1 -0.28), as a route frame's lens in BM_RouteMotionDepth/1 and BM_RouteFrameLens.
constexpr Distortion kEurocDistortion{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};

// `image` as seen through `lens`: each raw pixel shows what its undistorted place shows.
cv::Mat ThroughLens(const depth::Lens& lens, const cv::Mat& image, int interpolation) {
  if (!lens.distorted()) return image;
  cv::Mat raw;
  cv::remap(image, raw, lens.pinhole_at(), cv::noArray(), interpolation, cv::BORDER_CONSTANT, cv::Scalar());
  return raw;
}

// Depth of one route frame from the frames 1.3 m before and after it (two stereo matchings): once per frame of
// either route when change.route.depth is on. /0: a pinhole camera; /1: the frames seen through EuRoC cam0's lens,
// undone in the matching. Counters: the share of pixels given depth, and of those the share within 5 % of the
// rendered depth.
void BM_RouteMotionDepth(benchmark::State& state) {
  const depth::Lens lens(kCamera, state.range(0) == 1 ? kEurocDistortion : Distortion{});
  const std::vector<sim::WorldObject> objects = sim::PlaceObjects(30, 1);
  const View here = Render(20.0, objects, {});
  const View before = Render(18.7, objects, {}), after = Render(21.3, objects, {});
  const std::vector<change::RouteNeighbour> neighbours = {
      {ThroughLens(lens, before.image, cv::INTER_LINEAR), before.sample},
      {ThroughLens(lens, after.image, cv::INTER_LINEAR), after.sample}};
  const cv::Mat image = ThroughLens(lens, here.image, cv::INTER_LINEAR);
  const cv::Mat truth_m = ThroughLens(lens, here.depth_m, cv::INTER_NEAREST);
  change::KeyFrameView view;
  for (auto _ : state) {
    view = change::KeyFrameView();
    view.image = image;
    change::AddMotionDepth(neighbours, lens, here.sample, change::RouteDepthOptions{}, &view);
  }
  int known = 0, within = 0;
  for (int y = 0; y < view.depth.rows; ++y) {
    for (int x = 0; x < view.depth.cols; ++x) {
      const float z = view.depth.at<float>(y, x), truth = truth_m.at<float>(y, x);
      if (!(z > 0.0f) || !(truth > 0.0f)) continue;
      ++known;
      within += std::abs(z - truth) <= 0.05f * truth;
    }
  }
  state.counters["known_share"] = static_cast<double>(known) / view.depth.total();
  state.counters["within_5_percent"] = known > 0 ? static_cast<double>(within) / known : 0.0;
}
BENCHMARK(BM_RouteMotionDepth)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A route's lens at 376x240 (each pixel's undistorted place): once per patrol compared, when its lens distorts.
void BM_RouteFrameLens(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(depth::Lens(kCamera, kEurocDistortion).pinhole_at().data);
}
BENCHMARK(BM_RouteFrameLens)->Unit(benchmark::kMillisecond);

// Decoding one route frame and finding its SIFT features: done once per frame of either route.
void BM_RouteFrameFeatures(benchmark::State& state) {
  const RouteFrame frame = RouteFrameAt(20.0, sim::PlaceObjects(30, 1), {}, 0.0);
  change::KeyFrameView view;
  for (auto _ : state) view = change::RouteFrameView(frame, change::RouteCompareOptions{}.max_features);
  state.counters["features"] = static_cast<double>(view.points.size());
}
BENCHMARK(BM_RouteFrameFeatures)->Unit(benchmark::kMillisecond);

// Registering one candidate prior frame onto a current frame: max_candidates of them per current frame.
void BM_RouteCandidateRegistration(benchmark::State& state) {
  const std::vector<sim::WorldObject> objects = sim::PlaceObjects(30, 1);
  const change::RouteCompareOptions options;
  const change::KeyFrameView prior = change::RouteFrameView(RouteFrameAt(20.0, objects, {}, 0.0), options.max_features);
  const change::KeyFrameView current =
      change::RouteFrameView(RouteFrameAt(20.4, objects, sim::DrawLighting(1, 2), 0.0), options.max_features);
  change::Registration registration;
  for (auto _ : state) registration = change::Register(prior, current, change::AppearanceOptions{});
  state.counters["inliers"] = registration.inliers;
}
BENCHMARK(BM_RouteCandidateRegistration)->Unit(benchmark::kMillisecond);

// Comparing one registered pair of route frames (an object removed): once per compared frame, twice where the
// first comparison found a region.
void BM_RouteComparedPair(benchmark::State& state) {
  std::vector<sim::WorldObject> objects = sim::PlaceObjects(30, 1);
  const std::size_t removed = SouthObject(objects);
  const double x = objects[removed].centre.x();
  const change::RouteCompareOptions options;
  const change::KeyFrameView prior = change::RouteFrameView(RouteFrameAt(x, objects, {}, 0.0), options.max_features);
  objects.erase(objects.begin() + static_cast<std::ptrdiff_t>(removed));
  const change::KeyFrameView current =
      change::RouteFrameView(RouteFrameAt(x + 0.3, objects, sim::DrawLighting(1, 2), 0.0), options.max_features);
  const change::Registration registration = change::Register(prior, current, change::AppearanceOptions{});
  change::AppearanceChange change;
  for (auto _ : state) change = change::CompareRegistered(prior, current, registration, change::AppearanceOptions{});
  state.counters["regions"] = static_cast<double>(change.regions.size());
}
BENCHMARK(BM_RouteComparedPair)->Unit(benchmark::kMillisecond);

// A whole route of 20 frames 1.3 m apart (a 20 s flight at the simulator's speed), aligned with one anchor,
// compared and voted; per frame = time / 20. Argument: change.route.depth on (1) or off (0).
void BM_RouteOfTwentyFrames(benchmark::State& state) {
  std::vector<sim::WorldObject> objects = sim::PlaceObjects(30, 1);
  const double x0 = objects[SouthObject(objects)].centre.x() - 13.0;
  std::vector<RouteFrame> prior, current;
  for (int i = 0; i < 20; ++i) prior.push_back(RouteFrameAt(x0 + 1.3 * i, objects, {}, i));
  objects.erase(objects.begin() + static_cast<std::ptrdiff_t>(SouthObject(objects)));
  for (int i = 0; i < 20; ++i) current.push_back(RouteFrameAt(x0 + 0.4 + 1.3 * i, objects, sim::DrawLighting(1, 2), i));
  change::RouteCompareOptions options;
  options.depth.enabled = state.range(0) != 0;
  change::RouteComparison comparison;
  for (auto _ : state) {
    comparison =
        change::CompareRoutes(prior, current, {{0, 0}}, options, change::AppearanceOptions{}, {kCamera, kCamera, true});
  }
  state.counters["pairs"] = static_cast<double>(comparison.pairs.size());
  state.counters["changes"] = static_cast<double>(comparison.changes.size());
}
BENCHMARK(BM_RouteOfTwentyFrames)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
