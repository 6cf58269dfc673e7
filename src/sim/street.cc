// The straight-street scene: facades with gaps in front of a far facade.
#include <cmath>

#include <opencv2/core.hpp>

#include "patrolmap/sim/flight.h"
#include "patrolmap/sim/village.h"

namespace patrolmap::sim {
namespace {

constexpr double kBuildingDepth = 8.0;  // extent of each near building away from the street [m]

// Adds a box building whose street facade runs from (x0, y) to (x1, y).
void AddBuilding(double x0, double x1, double y, double height, std::uint32_t seed, Scene* scene) {
  const int front = static_cast<int>(scene->textures.size());
  scene->textures.push_back(MakeFacadeTexture(x1 - x0, height, seed));
  scene->textures.push_back(MakeFacadeTexture(kBuildingDepth, height, seed + 1));
  const std::size_t first_wall = scene->walls.size();
  AddBox(Eigen::Vector2d(0.5 * (x0 + x1), y + kBuildingDepth / 2), 0.0, x1 - x0, kBuildingDepth, height, front, scene);
  scene->walls[first_wall + 1].texture = front + 1;
  scene->walls[first_wall + 3].texture = front + 1;
}

struct Facade {
  double x0 = 0.0, x1 = 0.0, depth = 0.0, height = 0.0;
};

std::vector<Facade> LayFacades(const StreetOptions& options) {
  cv::RNG rng(options.seed * 7919u + 17u);
  const auto draw = [&](double value, double low, double high) {
    return options.irregular ? value * rng.uniform(low, high) : value;
  };
  std::vector<Facade> facades;
  double x = 0.0;
  for (int i = 0; i < options.walls; ++i) {
    Facade facade;
    facade.x0 = x;
    facade.x1 = x + draw(options.wall_length_m, 0.6, 1.5);
    facade.depth = draw(options.near_depth_m, 0.8, 1.6);
    facade.height = draw(options.wall_height_m, 0.7, 1.3);
    facades.push_back(facade);
    x = facade.x1 + draw(options.gap_length_m, 0.5, 1.3);
  }
  return facades;
}

// Straight flight along +x at `speed` on average, with the optional yaw and speed swings.
std::function<PlatformState(double)> StreetTrajectory(double start, double speed, const StreetOptions& options) {
  const double yaw_period = options.yaw_period_s, speed_period = options.speed_period_s;
  const double yaw_amplitude = options.yaw_wobble_deg * M_PI / 180.0;
  const double variation = options.speed_variation;
  const double altitude = options.altitude_m;
  return [=](double t) {
    const double yaw_phase = 2.0 * M_PI * t / yaw_period, speed_phase = 2.0 * M_PI * t / speed_period;
    PlatformState state;
    // x(t) integrates speed * (1 + variation * sin(speed_phase)).
    const double x = speed * (t + variation * speed_period / (2.0 * M_PI) * (1.0 - std::cos(speed_phase)));
    state.position = Eigen::Vector3d(start + x, 0.0, altitude);
    state.velocity = Eigen::Vector3d(speed * (1.0 + variation * std::sin(speed_phase)), 0.0, 0.0);
    state.acceleration =
        Eigen::Vector3d(speed * variation * 2.0 * M_PI / speed_period * std::cos(speed_phase), 0.0, 0.0);
    state.heading = yaw_amplitude * std::sin(yaw_phase);
    state.yaw_rate = yaw_amplitude * 2.0 * M_PI / yaw_period * std::cos(yaw_phase);
    return state;
  };
}

}  // namespace

SimulatedFlight MakeStreetFlight(const StreetOptions& options, std::vector<Eigen::Vector2d>* gaps) {
  SimulatedFlight flight;
  flight.flight_id = "street";
  flight.mount_angle = options.mount_angle_deg * M_PI / 180.0;
  Scene& scene = flight.scene;
  const std::vector<Facade> facades = LayFacades(options);
  for (std::size_t i = 0; i < facades.size(); ++i) {
    const Facade& facade = facades[i];
    AddBuilding(facade.x0, facade.x1, facade.depth, facade.height, options.seed * 1000u + 10u * i, &scene);
    if (gaps != nullptr && i + 1 < facades.size()) gaps->emplace_back(facade.x1, facades[i + 1].x0);
  }
  const double street_end = facades.back().x1;
  const double margin = 4.0 * options.far_depth_m;
  scene.textures.push_back(
      MakeFacadeTexture(street_end + 2 * margin, 2.0 * options.wall_height_m, options.seed * 1000u + 999u));
  scene.walls.push_back({Eigen::Vector2d(-margin, options.far_depth_m),
                         Eigen::Vector2d(street_end + margin, options.far_depth_m), 2.0 * options.wall_height_m,
                         static_cast<int>(scene.textures.size()) - 1});
  scene.textures.push_back(MakeGroundTexture(scene.ground_tile_metres, options.seed * 1000u + 998u));
  scene.ground_texture = static_cast<int>(scene.textures.size()) - 1;

  const double start = 0.5 * (facades.front().x0 + facades.front().x1);
  const double length = 0.5 * (facades.back().x0 + facades.back().x1) - start;
  const double speed = options.static_camera ? 0.0 : options.speed_mps;
  flight.duration_s = options.static_camera ? 10.0 : length / options.speed_mps;
  flight.trajectory = StreetTrajectory(start, speed, options);
  return flight;
}

}  // namespace patrolmap::sim
