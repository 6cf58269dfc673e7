// The straight-street scene: facades with gaps in front of a far facade.
#include <cmath>

#include "patrolmap/sim/flight.h"

namespace patrolmap::sim {
namespace {

constexpr double kBuildingDepth = 8.0;  // extent of each near building away from the street [m]

// Adds a box building whose street facade runs from (x0, y) to (x1, y).
void AddBuilding(double x0, double x1, double y, double height, std::uint32_t seed, Scene* scene) {
  const double length = x1 - x0;
  const int front = static_cast<int>(scene->textures.size());
  scene->textures.push_back(MakeFacadeTexture(length, height, seed));
  scene->textures.push_back(MakeFacadeTexture(kBuildingDepth, height, seed + 1));
  const int side = front + 1;
  const Eigen::Vector2d a(x0, y), b(x1, y), c(x1, y + kBuildingDepth), d(x0, y + kBuildingDepth);
  scene->walls.push_back({a, b, height, front});
  scene->walls.push_back({b, c, height, side});
  scene->walls.push_back({c, d, height, front});
  scene->walls.push_back({d, a, height, side});
}

}  // namespace

SimulatedFlight MakeStreetFlight(const StreetOptions& options, std::vector<Eigen::Vector2d>* gaps) {
  SimulatedFlight flight;
  flight.flight_id = "street";
  Scene& scene = flight.scene;
  const double period = options.wall_length_m + options.gap_length_m;
  for (int i = 0; i < options.walls; ++i) {
    const double x0 = i * period;
    AddBuilding(x0, x0 + options.wall_length_m, options.near_depth_m, options.wall_height_m,
                options.seed * 1000u + 10u * i, &scene);
    if (gaps != nullptr && i + 1 < options.walls) gaps->emplace_back(x0 + options.wall_length_m, (i + 1) * period);
  }
  const double street_end = (options.walls - 1) * period + options.wall_length_m;
  const double margin = 4.0 * options.far_depth_m;
  scene.textures.push_back(MakeFacadeTexture(street_end + 2 * margin, 2.0 * options.wall_height_m,
                                             options.seed * 1000u + 999u));
  scene.walls.push_back({Eigen::Vector2d(-margin, options.far_depth_m),
                         Eigen::Vector2d(street_end + margin, options.far_depth_m), 2.0 * options.wall_height_m,
                         static_cast<int>(scene.textures.size()) - 1});
  scene.textures.push_back(MakeGroundTexture(scene.ground_tile_metres, options.seed * 1000u + 998u));
  scene.ground_texture = static_cast<int>(scene.textures.size()) - 1;

  const double start = 0.5 * options.wall_length_m;
  const double length = street_end - options.wall_length_m;
  const double speed = options.static_camera ? 0.0 : options.speed_mps;
  flight.duration_s = options.static_camera ? 10.0 : length / options.speed_mps;
  const double altitude = options.altitude_m;
  flight.trajectory = [start, speed, altitude](double t) {
    PlatformState state;
    state.position = Eigen::Vector3d(start + speed * t, 0.0, altitude);
    state.velocity = Eigen::Vector3d(speed, 0.0, 0.0);
    return state;
  };
  return flight;
}

}  // namespace patrolmap::sim
