#include "patrolmap/sim/scene.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace patrolmap::sim {
namespace {

cv::Rect MetresToRect(double x, double y, double width, double height, double texels_per_metre, int rows) {
  // y measured upwards from the ground; image rows grow downwards.
  const int left = static_cast<int>(x * texels_per_metre);
  const int top = rows - static_cast<int>((y + height) * texels_per_metre);
  return {left, top, std::max(1, static_cast<int>(width * texels_per_metre)),
          std::max(1, static_cast<int>(height * texels_per_metre))};
}

void AddNoise(cv::Mat* image, cv::RNG* rng, double sigma, int blur) {
  cv::Mat noise(image->size(), CV_16SC1);
  rng->fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  if (blur > 1) cv::blur(noise, noise, cv::Size(blur, blur));
  cv::Mat sum;
  image->convertTo(sum, CV_16SC1);
  sum += noise;
  sum.convertTo(*image, CV_8UC1);
}

void DrawBricks(cv::Mat* image, cv::RNG* rng, double texels_per_metre) {
  const int course = std::max(2, static_cast<int>(0.075 * texels_per_metre));
  const int brick = std::max(4, static_cast<int>(0.24 * texels_per_metre));
  for (int row = 0, y = 0; y < image->rows; ++row, y += course) {
    const int offset = (row % 2) * brick / 2;
    cv::line(*image, {0, y}, {image->cols, y}, cv::Scalar(rng->uniform(60, 90)), 1);
    for (int x = -offset; x < image->cols; x += brick) {
      cv::line(*image, {x, y}, {x, y + course}, cv::Scalar(rng->uniform(60, 90)), 1);
    }
  }
}

void DrawWindow(cv::Mat* image, const cv::Rect& frame, cv::RNG* rng) {
  cv::rectangle(*image, frame, cv::Scalar(rng->uniform(200, 250)), cv::FILLED);
  const cv::Rect glass(frame.x + frame.width / 10 + 1, frame.y + frame.height / 10 + 1, frame.width * 8 / 10 - 2,
                       frame.height * 8 / 10 - 2);
  cv::rectangle(*image, glass, cv::Scalar(rng->uniform(20, 70)), cv::FILLED);
  if (rng->uniform(0, 2) == 1) {
    cv::line(*image, {glass.x + glass.width / 2, glass.y}, {glass.x + glass.width / 2, glass.br().y}, cv::Scalar(220),
             2);
  }
  if (rng->uniform(0, 3) == 0) {  // a half-drawn blind
    cv::rectangle(*image, cv::Rect(glass.x, glass.y, glass.width, glass.height * rng->uniform(2, 8) / 10),
                  cv::Scalar(rng->uniform(120, 200)), cv::FILLED);
  }
}

void DrawSign(cv::Mat* image, const cv::Rect& board, cv::RNG* rng) {
  const int background = rng->uniform(0, 2) == 0 ? rng->uniform(10, 60) : rng->uniform(200, 250);
  cv::rectangle(*image, board, cv::Scalar(background), cv::FILLED);
  const int letters = rng->uniform(3, 9);
  const int pitch = std::max(2, board.width / (letters + 1));
  for (int i = 0; i < letters; ++i) {
    const cv::Point a(board.x + pitch / 2 + i * pitch, board.y + board.height / 5);
    const cv::Point b(a.x + rng->uniform(-pitch / 2, pitch / 2 + 1), board.y + board.height * 4 / 5);
    cv::line(*image, a, b, cv::Scalar(255 - background), std::max(1, board.height / 8));
  }
}

void DrawOpenings(cv::Mat* image, double width_m, double height_m, cv::RNG* rng, double texels_per_metre) {
  const double spacing = rng->uniform(2.2, 4.0);
  const double window_width = rng->uniform(0.8, 1.6);
  const double window_height = rng->uniform(1.0, 1.7);
  const double storey = rng->uniform(2.8, 3.4);
  const double margin = rng->uniform(0.4, spacing - window_width);
  for (double floor_y = 0.9; floor_y + window_height < height_m - 0.3; floor_y += storey) {
    for (double x = margin; x + window_width < width_m; x += spacing) {
      if (rng->uniform(0, 10) == 0) continue;  // a bricked-up window
      const bool door = floor_y < 1.0 && rng->uniform(0, 5) == 0;
      const double bottom = door ? 0.0 : floor_y;
      const double height = door ? 2.2 : window_height;
      DrawWindow(image, MetresToRect(x, bottom, window_width, height, texels_per_metre, image->rows), rng);
    }
  }
  const int signs = rng->uniform(0, 3);
  for (int i = 0; i < signs; ++i) {
    const double sign_width = rng->uniform(1.0, 3.0);
    const double x = rng->uniform(0.0, std::max(0.1, width_m - sign_width));
    DrawSign(image, MetresToRect(x, rng->uniform(2.3, 2.8), sign_width, 0.5, texels_per_metre, image->rows), rng);
  }
}

}  // namespace

Texture MakeTexture(cv::Mat level0, double texels_per_metre) {
  Texture texture;
  texture.texels_per_metre = texels_per_metre;
  texture.levels.push_back(std::move(level0));
  while (texture.levels.back().cols > 8 && texture.levels.back().rows > 8) {
    cv::Mat smaller;
    cv::pyrDown(texture.levels.back(), smaller);
    texture.levels.push_back(smaller);
  }
  return texture;
}

Texture MakeFacadeTexture(double width_m, double height_m, std::uint32_t seed, double texels_per_metre) {
  cv::RNG rng(seed);
  const int columns = std::max(8, static_cast<int>(width_m * texels_per_metre));
  const int rows = std::max(8, static_cast<int>(height_m * texels_per_metre));
  cv::Mat image(rows, columns, CV_8UC1, cv::Scalar(rng.uniform(110, 200)));
  AddNoise(&image, &rng, rng.uniform(6.0, 14.0), 3);
  if (rng.uniform(0, 3) == 0) DrawBricks(&image, &rng, texels_per_metre);
  DrawOpenings(&image, width_m, height_m, &rng, texels_per_metre);
  AddNoise(&image, &rng, 4.0, 1);
  return MakeTexture(image, texels_per_metre);
}

Texture MakeGroundTexture(double tile_metres, std::uint32_t seed, double texels_per_metre) {
  cv::RNG rng(seed);
  const int side = std::max(8, static_cast<int>(tile_metres * texels_per_metre));
  cv::Mat image(side, side, CV_8UC1, cv::Scalar(105));
  AddNoise(&image, &rng, 30.0, 5);
  for (int i = 0; i < 12; ++i) {
    const cv::Point centre(rng.uniform(0, side), rng.uniform(0, side));
    cv::circle(image, centre, rng.uniform(side / 40 + 1, side / 10 + 2), cv::Scalar(rng.uniform(60, 160)), cv::FILLED);
  }
  AddNoise(&image, &rng, 8.0, 1);
  return MakeTexture(image, texels_per_metre);
}

}  // namespace patrolmap::sim
