#include "patrolmap/depth/fusion.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "patrolmap/core/status.h"

namespace patrolmap::depth {

DepthFusion::DepthFusion(const CameraIntrinsics& camera, const FusionOptions& options)
    : camera_(camera), options_(options), kept_(static_cast<std::size_t>(std::max(0, options.frames))) {
  PATROLMAP_CHECK(options.shared_variance >= 0.0 && options.shared_variance <= 1.0);  // StereoOptions::IsValid
  // ErrorScale of 1 to frames + 1 views, looked up per pixel.
  scales_.resize(kept_.size() + 2);
  for (std::size_t views = 1; views < scales_.size(); ++views) {
    scales_[views] = static_cast<float>(ErrorScale(static_cast<int>(views)));
  }
}

double DepthFusion::ErrorScale(int views) const {
  const double shared = options_.shared_variance;
  return views < 1 ? 0.0 : std::sqrt(shared + (1.0 - shared) / views);
}

bool DepthFusion::DepthSeenBy(const Kept& kept, const Eigen::Vector3d& world, const CameraPoseSample& pose,
                              double* z) const {
  const Eigen::Vector3d in_kept = kept.pose.ToCamera(world);
  if (in_kept.z() <= 0.0) return false;
  const double column = camera_.fx * in_kept.x() / in_kept.z() + camera_.cx;
  const double row = camera_.fy * in_kept.y() / in_kept.z() + camera_.cy;
  if (!(column > -0.5 && row > -0.5 && column < kept.depth_m.cols - 0.5 && row < kept.depth_m.rows - 0.5)) {
    return false;  // outside that frame (tested before rounding: a point almost beside the camera lands far off)
  }
  const int u = static_cast<int>(std::lround(column)), v = static_cast<int>(std::lround(row));
  const double depth = kept.depth_m.at<float>(v, u);
  if (depth <= 0.0) return false;
  *z = pose.ToCamera(kept.pose.ToWorld(InCamera(u, v, depth))).z();
  return true;
}

void DepthFusion::Fuse(const CameraPoseSample& pose, int step, cv::Mat* depth_m, cv::Mat* error_scale) {
  error_scale->create(depth_m->size(), CV_32F);
  error_scale->setTo(0);
  const int frames = static_cast<int>(kept_.size());
  if (frames > 0) depth_m->copyTo(raw_);  // kept unfused; the buffer is reused
  const int first = step / 2;
  for (int y = first; y < depth_m->rows; y += step) {
    float* row = depth_m->ptr<float>(y);
    float* scale = error_scale->ptr<float>(y);
    for (int x = first; x < depth_m->cols; x += step) {
      const double z = row[x];
      if (z <= 0.0) continue;
      const Eigen::Vector3d world = pose.ToWorld(InCamera(x, y, z));
      double sum = z;
      int n = 1;
      for (int back = 1; back <= count_; ++back) {
        double other = 0.0;
        const Kept& kept = kept_[(next_ - back + frames) % frames];
        if (!DepthSeenBy(kept, world, pose, &other)) continue;
        const double gate = options_.gate_sigmas * std::hypot(Sigma(z), Sigma(other));
        if (std::abs(other - z) > gate) continue;
        sum += other;
        ++n;
      }
      row[x] = static_cast<float>(sum / n);
      scale[x] = scales_[n];
    }
  }
  if (frames == 0) return;
  std::swap(kept_[next_].depth_m, raw_);  // the oldest frame's buffer becomes the next raw_
  kept_[next_].pose = pose;
  next_ = (next_ + 1) % frames;
  count_ = std::min(count_ + 1, frames);
}

}  // namespace patrolmap::depth
