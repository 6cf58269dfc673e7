#include "patrolmap/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "patrolmap/core/status.h"
#include "plane.h"

namespace patrolmap::sim {
namespace {

constexpr double kNearestDepth = 0.05;  // surfaces closer than this are ignored [m]

std::uint8_t Bilinear(const cv::Mat& image, double u, double v, bool wrap) {
  const double x = u - 0.5, y = v - 0.5;
  int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  int x1 = x0 + 1, y1 = y0 + 1;
  const auto fix = [wrap](int value, int size) {
    if (wrap) return ((value % size) + size) % size;
    return std::clamp(value, 0, size - 1);
  };
  x0 = fix(x0, image.cols), x1 = fix(x1, image.cols), y0 = fix(y0, image.rows), y1 = fix(y1, image.rows);
  const unsigned char* row0 = image.ptr<unsigned char>(y0);
  const unsigned char* row1 = image.ptr<unsigned char>(y1);
  const double top = row0[x0] + fx * (row0[x1] - row0[x0]);
  const double bottom = row1[x0] + fx * (row1[x1] - row1[x0]);
  return static_cast<std::uint8_t>(top + fy * (bottom - top) + 0.5);
}

}  // namespace

Lighting DrawLighting(std::uint32_t seed, int flight) {
  cv::RNG rng(seed * 7368787u + static_cast<std::uint32_t>(flight) * 9973u + 3u);
  Lighting lighting;
  lighting.gain = rng.uniform(0.7, 1.3);
  lighting.gamma = rng.uniform(0.8, 1.25);
  lighting.sun_azimuth = rng.uniform(0.0, 2 * M_PI);
  lighting.sun_elevation = rng.uniform(20.0, 60.0) * M_PI / 180.0;
  lighting.ambient = 0.55;
  lighting.noise_sigma = 2.0;
  lighting.noise_seed = seed * 31u + static_cast<std::uint32_t>(flight);
  return lighting;
}

Eigen::Matrix3d WorldFromCameraRotation(double yaw) {
  const Eigen::Vector3d forward(std::cos(yaw), std::sin(yaw), 0.0);
  const Eigen::Vector3d right(std::sin(yaw), -std::cos(yaw), 0.0);
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  Eigen::Matrix3d rotation;
  rotation << right, down, forward;
  return rotation;
}

bool Project(const CameraIntrinsics& camera, const CameraPose& pose, const Eigen::Vector3d& point,
             Eigen::Vector2d* pixel) {
  const Eigen::Vector3d in_camera = WorldFromCameraRotation(pose.yaw).transpose() * (point - pose.position);
  if (in_camera.z() <= kNearestDepth) return false;
  *pixel = {camera.fx * in_camera.x() / in_camera.z() + camera.cx,
            camera.fy * in_camera.y() / in_camera.z() + camera.cy};
  return true;
}

std::uint8_t SampleTexture(const Texture& texture, double u, double v, double footprint, bool wrap) {
  int level = footprint > 1.0 ? static_cast<int>(std::log2(footprint)) : 0;
  level = std::min(level, static_cast<int>(texture.levels.size()) - 1);
  const double scale = 1.0 / static_cast<double>(1 << level);
  return Bilinear(texture.levels[level], u * scale, v * scale, wrap);
}

Renderer::Renderer(const Scene* scene, const CameraIntrinsics& camera, const Lighting& lighting)
    : scene_(scene), camera_(camera), lighting_(lighting) {
  PATROLMAP_CHECK(scene != nullptr && camera.valid());
  for (const Wall& wall : scene->walls) {
    PATROLMAP_CHECK(wall.texture >= 0 && wall.texture < static_cast<int>(scene->textures.size()));
    const Eigen::Vector2d along = (wall.end - wall.start).normalized();
    normals_.emplace_back(along.y(), -along.x());
  }
  sun_ = std::cos(lighting.sun_elevation) *
         Eigen::Vector2d(std::cos(lighting.sun_azimuth), std::sin(lighting.sun_azimuth));
  ground_shade_ = static_cast<float>(lighting.ambient + (1.0 - lighting.ambient) * std::sin(lighting.sun_elevation));
  exposure_.resize(4 * 400);
  for (std::size_t i = 0; i < exposure_.size(); ++i) {
    const double normalised = std::min(1.0, lighting.gain * (i / 4.0) / 255.0);
    exposure_[i] = static_cast<std::uint8_t>(255.0 * std::pow(normalised, 1.0 / lighting.gamma) + 0.5);
  }
}

std::uint8_t Renderer::Expose(double linear) const {
  const std::size_t index = std::min(exposure_.size() - 1, static_cast<std::size_t>(std::max(0.0, linear) * 4.0));
  return exposure_[index];
}

void Renderer::AddNoise(std::uint64_t frame, cv::Mat* image) const {
  if (lighting_.noise_sigma <= 0.0) return;
  cv::RNG rng(lighting_.noise_seed * 1000003ull + frame);
  cv::Mat noise(image->size(), CV_16SC1);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, lighting_.noise_sigma);
  cv::Mat sum;
  image->convertTo(sum, CV_16SC1);
  sum += noise;
  sum.convertTo(*image, CV_8UC1);
}

void Renderer::IntersectColumn(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction) {
  hits_.clear();
  for (std::size_t i = 0; i < scene_->walls.size(); ++i) {
    const Wall& wall = scene_->walls[i];
    const Eigen::Vector2d along = wall.end - wall.start;
    const double denominator = Cross(direction, along);
    if (std::abs(denominator) < 1e-12) continue;
    const Eigen::Vector2d offset = wall.start - origin;
    const double depth = Cross(offset, along) / denominator;
    const double fraction = Cross(offset, direction) / denominator;
    if (depth < kNearestDepth || fraction < 0.0 || fraction > 1.0) continue;
    const Eigen::Vector2d seen_side = normals_[i].dot(direction) < 0 ? normals_[i] : Eigen::Vector2d(-normals_[i]);
    const double lit = std::max(0.0, seen_side.dot(sun_));
    const float shade = static_cast<float>(lighting_.ambient + (1.0 - lighting_.ambient) * lit);
    hits_.push_back({depth, fraction * along.norm(), static_cast<int>(i), shade});
  }
  std::sort(hits_.begin(), hits_.end(), [](const Hit& a, const Hit& b) { return a.depth < b.depth; });
}

std::uint8_t Renderer::ShadeGround(const Eigen::Vector2d& point, double depth) const {
  if (scene_->ground_texture < 0) return Expose(scene_->ground_grey * ground_shade_);
  const Texture& texture = scene_->textures[scene_->ground_texture];
  const double footprint = depth * texture.texels_per_metre / camera_.fx;
  return Expose(ground_shade_ * SampleTexture(texture, point.x() * texture.texels_per_metre,
                                              point.y() * texture.texels_per_metre, footprint, true));
}

std::uint8_t Renderer::ShadeWall(const Hit& hit, double z) const {
  const Wall& wall = scene_->walls[hit.wall];
  const Texture& texture = scene_->textures[wall.texture];
  const double footprint = hit.depth * texture.texels_per_metre / camera_.fx;
  return Expose(hit.shade * SampleTexture(texture, hit.s * texture.texels_per_metre,
                                          (wall.height - z) * texture.texels_per_metre, footprint, false));
}

// True when a ray that passes over the top of wall hits_[index] comes down on
// the roof of that wall's box before leaving it.
bool Renderer::HitsRoof(std::size_t index, double height, double slope) const {
  const int box = scene_->walls[hits_[index].wall].box;
  if (box < 0) return false;
  for (std::size_t next = index + 1; next < hits_.size(); ++next) {
    const Wall& wall = scene_->walls[hits_[next].wall];
    if (wall.box == box) return height - slope * hits_[next].depth <= wall.height;
  }
  return false;
}

// What the ray of a pixel row sees in the current column (hits_ already found).
Renderer::Surface Renderer::SurfaceAt(double height, double slope) const {
  for (std::size_t i = 0; i < hits_.size(); ++i) {
    const Hit& hit = hits_[i];
    const Wall& wall = scene_->walls[hit.wall];
    const double z = height - slope * hit.depth;
    if (z > wall.height) {  // the ray passes over this wall, maybe onto its box's roof
      if (HitsRoof(i, height, slope)) return {SurfaceKind::kRoof, static_cast<int>(i), (height - wall.height) / slope};
      continue;
    }
    if (z >= 0.0) return {SurfaceKind::kWall, static_cast<int>(i), hit.depth};
    break;  // the ray reaches the ground before this wall
  }
  if (slope > 0.0) return {SurfaceKind::kGround, -1, height / slope};
  return {SurfaceKind::kSky, -1, 0.0};
}

void Renderer::ShadeColumn(int column, const CameraPose& pose, const Eigen::Vector2d& direction, cv::Mat* image) const {
  const double height = pose.position.z();
  for (int row = 0; row < image->rows; ++row) {
    const double slope = (row - camera_.cy) / camera_.fy;  // metres down per metre of depth
    const Surface surface = SurfaceAt(height, slope);
    std::uint8_t grey = 0;
    switch (surface.kind) {
      case SurfaceKind::kWall: grey = ShadeWall(hits_[surface.hit], height - slope * surface.depth); break;
      case SurfaceKind::kRoof:
        grey = Expose(ground_shade_ * scene_->roof_grey[scene_->walls[hits_[surface.hit].wall].box]);
        break;
      case SurfaceKind::kGround:
        grey = ShadeGround(pose.position.head<2>() + surface.depth * direction, surface.depth);
        break;
      case SurfaceKind::kSky: grey = Expose(scene_->sky_grey); break;
    }
    image->at<std::uint8_t>(row, column) = grey;
  }
}

void Renderer::RenderDepth(const CameraPose& pose, cv::Mat* depth_mm) {
  depth_mm->create(camera_.height, camera_.width, CV_16UC1);
  const Eigen::Matrix3d rotation = WorldFromCameraRotation(pose.yaw);
  for (int column = 0; column < camera_.width; ++column) {
    const Eigen::Vector2d direction =
        rotation.col(2).head<2>() + ((column - camera_.cx) / camera_.fx) * rotation.col(0).head<2>();
    IntersectColumn(pose.position.head<2>(), direction);
    for (int row = 0; row < camera_.height; ++row) {
      const double depth = SurfaceAt(pose.position.z(), (row - camera_.cy) / camera_.fy).depth;
      depth_mm->at<std::uint16_t>(row, column) = static_cast<std::uint16_t>(std::min(65535.0, depth * 1000.0 + 0.5));
    }
  }
}

void Renderer::Render(const CameraPose& pose, cv::Mat* image, std::uint64_t frame) {
  image->create(camera_.height, camera_.width, CV_8UC1);
  const Eigen::Matrix3d rotation = WorldFromCameraRotation(pose.yaw);
  const Eigen::Vector2d forward = rotation.col(2).head<2>();
  const Eigen::Vector2d right = rotation.col(0).head<2>();
  for (int column = 0; column < camera_.width; ++column) {
    const Eigen::Vector2d direction = forward + ((column - camera_.cx) / camera_.fx) * right;
    IntersectColumn(pose.position.head<2>(), direction);
    ShadeColumn(column, pose, direction, image);
  }
  AddNoise(frame, image);
}

void Renderer::ColumnDepths(const CameraPose& pose, std::vector<double>* depths) {
  depths->assign(camera_.width, std::numeric_limits<double>::infinity());
  const Eigen::Matrix3d rotation = WorldFromCameraRotation(pose.yaw);
  for (int column = 0; column < camera_.width; ++column) {
    const Eigen::Vector2d direction =
        rotation.col(2).head<2>() + ((column - camera_.cx) / camera_.fx) * rotation.col(0).head<2>();
    IntersectColumn(pose.position.head<2>(), direction);
    for (const Hit& hit : hits_) {
      if (scene_->walls[hit.wall].height >= pose.position.z()) {
        (*depths)[column] = hit.depth;
        break;
      }
    }
  }
}

}  // namespace patrolmap::sim
