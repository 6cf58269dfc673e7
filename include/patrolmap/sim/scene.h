// A 2.5D world for the flight simulator: vertical textured walls standing on a
// textured ground plane under a plain sky. World frame: x east, y north, z up
// [metres]. Buildings are closed rings of walls.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace patrolmap::sim {

// A texture with a mip chain; sampled with bilinear filtering at the level
// that matches the footprint of a pixel.
struct Texture {
  std::vector<cv::Mat> levels;  // CV_8UC1, level 0 full size, each next half size
  double texels_per_metre = 40.0;
};

// A vertical rectangle from `start` to `end` on the ground, `height` tall.
// Texture coordinate s runs from start to end [m], t upwards from the ground [m].
struct Wall {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  Eigen::Vector2d end = Eigen::Vector2d::Zero();
  double height = 0.0;
  int texture = 0;  // index into Scene::textures
  int box = -1;     // the closed box this wall belongs to (its roof is drawn), -1 for a lone wall
};

struct Scene {
  std::vector<Wall> walls;
  std::vector<Texture> textures;
  int ground_texture = -1;          // tiled over the ground; -1 = flat grey
  double ground_tile_metres = 8.0;  // side of one ground texture tile [m]
  std::uint8_t sky_grey = 215;
  std::uint8_t ground_grey = 110;
  std::vector<std::uint8_t> roof_grey;  // per box id
};

// A procedural facade texture: plaster or brick noise, a grid of windows and
// doors, and a few signs, all drawn from `seed`. `width_m` x `height_m` metres.
Texture MakeFacadeTexture(double width_m, double height_m, std::uint32_t seed, double texels_per_metre = 40.0);

// A ground tile texture (gravel noise with patches) drawn from `seed`.
Texture MakeGroundTexture(double tile_metres, std::uint32_t seed, double texels_per_metre = 20.0);

// Builds the mip chain of a level-0 image.
Texture MakeTexture(cv::Mat level0, double texels_per_metre);

}  // namespace patrolmap::sim
