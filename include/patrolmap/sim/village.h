// A procedural village like the paper's test site (paper 002 §IV: one- and
// two-storey buildings, passages, an artificial village): two blocks of box
// buildings separated by a passage, ringed by streets and an outer row of
// buildings. Layout [m], x east, y north:
//
//   outer row  y = 42 .. 50 ----------------------------------------
//   street     path of the loops at y = 36
//   block A1   x =  0 .. 18, y = 0 .. 30   passage x = 18 .. 28   block A2 x = 28 .. 46
//   street     path of the loops at y = -6
//   outer row  y = -20 .. -12 -------------------------------------
//
// Routes are flown counter-clockwise so that a camera looking left faces the blocks.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "patrolmap/sim/route.h"
#include "patrolmap/sim/scene.h"

namespace patrolmap::sim {

struct VillageOptions {
  std::uint32_t seed = 1;
  int alike_facade_pairs = 2;  // facade pairs that share one texture (paper Fig. 7 false loop closure)
};

struct Village {
  Scene scene;
  int building_count = 0;
  std::vector<std::pair<int, int>> alike_walls;  // indices into scene.walls sharing a texture
};

Village MakeVillage(const VillageOptions& options);

// The paper's three experiments through the village (paper: ~375, ~155 and
// ~85 m): "double-loop" (two laps around both blocks, 390 m flown), "inner-loop"
// (around block A1 through the passage, 137 m) and "l-shape" (along A1's south
// side, north through the passage, west along its north side, 82 m). Fails
// for other names.
Status RoutePreset(const std::string& name, Route* route);

// Adds a box (four walls and a roof) to a scene: footprint centred at `centre`,
// `length` along `yaw`, `width` across, `height` tall; `texture` for every side.
// Returns the box id.
int AddBox(const Eigen::Vector2d& centre, double yaw, double length, double width, double height, int texture,
           Scene* scene);

}  // namespace patrolmap::sim
