#include "patrolmap/sim/village.h"

#include <cmath>

#include <opencv2/core.hpp>

namespace patrolmap::sim {
namespace {

struct Rect {
  double x0, y0, x1, y1;
};

// One side of a block or of the outer row: buildings are laid from `from` towards
// `to`, their facades on that line, extending `inward` (a unit normal) away from the street.
struct Side {
  Eigen::Vector2d from, to, inward;
};

int AddTexture(Texture texture, Scene* scene) {
  scene->textures.push_back(std::move(texture));
  return static_cast<int>(scene->textures.size()) - 1;
}

class VillageBuilder {
 public:
  explicit VillageBuilder(const VillageOptions& options) : rng_(options.seed * 40503u + 7u), seed_(options.seed) {}

  // Buildings along a side: lengths 5-12 m, a gap of 3-7 m after 60 % of them, depth 6-9 m,
  // one storey (3.5-4.5 m, 60 %) or two (6-7.5 m).
  void FillSide(const Side& side, Village* village) {
    const double side_length = (side.to - side.from).norm();
    const Eigen::Vector2d along = (side.to - side.from) / side_length;
    for (double u = 0.0; u < side_length - 2.0;) {
      const double length = std::min(rng_.uniform(5.0, 12.0), side_length - u);
      const double depth = rng_.uniform(6.0, 9.0);
      const double height = rng_.uniform(0, 10) < 6 ? rng_.uniform(3.5, 4.5) : rng_.uniform(6.0, 7.5);
      const Eigen::Vector2d centre = side.from + (u + length / 2) * along + (depth / 2) * side.inward;
      AddBuilding(centre, std::atan2(along.y(), along.x()), length, depth, height, village);
      u += length + (rng_.uniform(0, 10) < 6 ? rng_.uniform(3.0, 7.0) : 0.0);
    }
  }

  // Gives facade pairs the same texture: the street faces of two buildings far apart.
  void MakeAlike(int pairs, Village* village) {
    const int buildings = static_cast<int>(street_walls_.size());
    for (int i = 0; i < pairs && buildings >= 4; ++i) {
      const int a = rng_.uniform(0, buildings / 2), b = buildings / 2 + rng_.uniform(0, buildings / 2);
      Wall& copy = village->scene.walls[street_walls_[b]];
      const Wall& original = village->scene.walls[street_walls_[a]];
      copy.texture = original.texture;
      village->alike_walls.emplace_back(street_walls_[a], street_walls_[b]);
    }
  }

 private:
  void AddBuilding(const Eigen::Vector2d& centre, double yaw, double length, double depth, double height,
                   Village* village) {
    Scene& scene = village->scene;
    const std::uint32_t texture_seed = seed_ * 100000u + 10u * village->building_count;
    const int facade = AddTexture(MakeFacadeTexture(length, height, texture_seed), &scene);
    const int side = AddTexture(MakeFacadeTexture(depth, height, texture_seed + 1), &scene);
    const int first_wall = static_cast<int>(scene.walls.size());
    AddBox(centre, yaw, length, depth, height, facade, &scene);
    scene.walls[first_wall + 1].texture = side;
    scene.walls[first_wall + 3].texture = side;
    street_walls_.push_back(first_wall);  // the first wall faces the street
    ++village->building_count;
  }

  cv::RNG rng_;
  std::uint32_t seed_;
  std::vector<int> street_walls_;
};

void FillBlock(const Rect& block, VillageBuilder* builder, Village* village) {
  // Counter-clockwise around the block; facades on the block edge, buildings inside.
  builder->FillSide({{block.x0, block.y0}, {block.x1, block.y0}, {0, 1}}, village);
  builder->FillSide({{block.x1, block.y0}, {block.x1, block.y1}, {-1, 0}}, village);
  builder->FillSide({{block.x1, block.y1}, {block.x0, block.y1}, {0, -1}}, village);
  builder->FillSide({{block.x0, block.y1}, {block.x0, block.y0}, {1, 0}}, village);
}

void FillOuterRow(const Rect& inner, VillageBuilder* builder, Village* village) {
  // Facades on the rectangle, buildings outside it.
  builder->FillSide({{inner.x0, inner.y0}, {inner.x1, inner.y0}, {0, -1}}, village);
  builder->FillSide({{inner.x1, inner.y0}, {inner.x1, inner.y1}, {1, 0}}, village);
  builder->FillSide({{inner.x1, inner.y1}, {inner.x0, inner.y1}, {0, 1}}, village);
  builder->FillSide({{inner.x0, inner.y1}, {inner.x0, inner.y0}, {-1, 0}}, village);
}

}  // namespace

int AddBox(const Eigen::Vector2d& centre, double yaw, double length, double width, double height, int texture,
           Scene* scene) {
  const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)), across(-std::sin(yaw), std::cos(yaw));
  const Eigen::Vector2d corners[4] = {
      centre - length / 2 * along - width / 2 * across, centre + length / 2 * along - width / 2 * across,
      centre + length / 2 * along + width / 2 * across, centre - length / 2 * along + width / 2 * across};
  const int box = static_cast<int>(scene->roof_grey.size());
  scene->roof_grey.push_back(static_cast<std::uint8_t>(70 + (box * 37) % 60));
  for (int i = 0; i < 4; ++i) scene->walls.push_back({corners[i], corners[(i + 1) % 4], height, texture, box});
  return box;
}

Village MakeVillage(const VillageOptions& options) {
  Village village;
  VillageBuilder builder(options);
  FillBlock({0.0, 0.0, 18.0, 30.0}, &builder, &village);
  FillBlock({28.0, 0.0, 46.0, 30.0}, &builder, &village);
  FillOuterRow({-12.0, -12.0, 58.0, 42.0}, &builder, &village);
  builder.MakeAlike(options.alike_facade_pairs, &village);
  Scene& scene = village.scene;
  scene.ground_texture =
      AddTexture(MakeGroundTexture(scene.ground_tile_metres, options.seed * 100000u + 99999u), &scene);
  return village;
}

Status RoutePreset(const std::string& name, Route* route) {
  using P = Eigen::Vector2d;
  route->name = name;
  if (name == "double-loop") {
    route->waypoints = {P(10, -6), P(52, -6), P(52, 36), P(-6, 36), P(-6, -6),
                        P(52, -6), P(52, 36), P(-6, 36), P(-6, -6), P(10, -6)};
  } else if (name == "inner-loop") {
    route->waypoints = {P(5, -6), P(23, -6), P(23, 36), P(-6, 36), P(-6, -6), P(5, -6)};
  } else if (name == "l-shape") {
    route->waypoints = {P(-6, -6), P(23, -6), P(23, 36), P(9, 36)};
  } else {
    return Status::InvalidArgument("unknown route '" + name + "' (double-loop, inner-loop, l-shape or a CSV file)");
  }
  return Status::Ok();
}

}  // namespace patrolmap::sim
