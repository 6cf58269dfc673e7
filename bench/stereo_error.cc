// Stereo matching error against true depth (BENCHMARKS.md, "Stereo depth", session 17).
//
//   stereo_error [--cancel-locking] LOG [STEP]
//     A log with cam0/, cam1/ (and their sensor.yaml) and depth0/ of the same times, such as a simulated one
//     (`patrolmap simulate --stereo 0.5 --depth`): every STEP-th pair (default 60) is matched with the default
//     stereo options and each depth compared with depth0/'s, as disparity f * b / z.
//   stereo_error [--cancel-locking] --middlebury LEFT RIGHT TRUTH NUM_DISPARITIES
//     A rectified pair with its 8-bit true disparity (0 = unknown), matched with the defaults and that range.
//   stereo_error [--cancel-locking] --shared LOG [STEP]
//     How much of the error depth frames share where they see the same surface (depth.stereo.fuse_shared_variance,
//     session 28): every STEP-th pair (default 6: 5 Hz at 30 Hz) against the 4 before it, with the log's poses.
//
// Prints the pixels compared, the share off by more than 3 px, and the mean and rms of the rest; for a log also
// the mean per metre of true depth, per grey level of the left image's 7x7 standard deviation and per tenth of the
// true disparity's fraction. --cancel-locking matches with depth.stereo.cancel_pixel_locking on.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "patrolmap/depth/stereo.h"
#include "patrolmap/io/patrol_sensors.h"
#include "patrolmap/io/readers.h"

namespace {

using namespace patrolmap;

constexpr double kGrossPx = 3.0;
// The error per tenth of the true disparity's fraction (SGBM's sub-pixel fit pulls disparities towards whole
// pixels) is counted only beyond this depth [m]: off the ground right under the camera, whose few depths fill
// a few tenths alone.
constexpr float kFractionBeyondM = 7.0f;

struct Mean {
  double sum = 0.0, squares = 0.0;
  long count = 0;
  void Add(double e) { sum += e, squares += e * e, ++count; }
};

struct Errors {
  Mean all;
  long gross = 0;
  std::map<int, Mean> by_depth, by_texture, by_fraction;
};

int Fail(const std::string& message) {
  std::fprintf(stderr, "error: %s\n", message.c_str());
  return 1;
}

void Print(const Errors& e, bool bins) {
  const long compared = e.all.count + e.gross;
  if (compared == 0) {
    std::printf("no pixel has both a measured and a true disparity\n");
    return;
  }
  const double mean = e.all.sum / std::max(1L, e.all.count);
  std::printf("pixels %ld, off by more than %.0f px %.3f %%, the rest: mean %.3f px, rms %.3f px\n", compared, kGrossPx,
              100.0 * e.gross / compared, mean, std::sqrt(e.all.squares / std::max(1L, e.all.count)));
  if (!bins) return;
  for (const auto& [metre, m] : e.by_depth)
    std::printf("true depth %2d m: mean %+.3f px (%ld pixels)\n", metre, m.sum / m.count, m.count);
  for (const auto& [grey, m] : e.by_texture)
    std::printf("left 7x7 std %2d%s: mean %+.3f px (%ld pixels)\n", grey, grey == 20 ? "+" : "", m.sum / m.count,
                m.count);
  for (const auto& [tenth, m] : e.by_fraction)
    std::printf("true disparity's fraction 0.%d: mean %+.3f px, rms %.3f px (%ld pixels)\n", tenth, m.sum / m.count,
                std::sqrt(m.squares / m.count), m.count);
}

// The left image's local standard deviation over 7x7 pixels.
cv::Mat LocalDeviation(const cv::Mat& left) {
  cv::Mat image, mean, squares, deviation;
  left.convertTo(image, CV_32F);
  cv::blur(image, mean, cv::Size(7, 7));
  cv::blur(image.mul(image), squares, cv::Size(7, 7));
  cv::sqrt(cv::max(squares - mean.mul(mean), 0.0), deviation);
  return deviation;
}

// A log's stereo pairs and its depth0/ images by time, with the matcher for its calibration.
struct LogPairs {
  std::vector<DepthSample> pairs;
  std::map<TimestampNs, std::string> truth;
  std::unique_ptr<depth::StereoDepth> stereo;
  CameraIntrinsics camera;  // the left camera's, in which depth is given
};

int ReadLog(const std::string& log, const depth::StereoOptions& options, LogPairs* out) {
  std::unique_ptr<io::FrameSource> source;
  Status status = io::OpenEuroc(log, &source);
  if (!status.ok()) return Fail(status.message());
  if (!source->info().stereo) return Fail(log + ": no stereo pair (cam1/ with sensor.yaml)");
  Frame frame;
  while ((status = source->Next(false, &frame)).ok()) {
    for (DepthSample& d : frame.depth) {
      if (d.stereo()) {
        out->pairs.push_back(std::move(d));
      } else {
        out->truth[d.timestamp_ns] = d.path;
      }
    }
  }
  if (!status.end_of_stream()) return Fail(status.message());
  if (out->truth.empty()) return Fail(log + ": no depth0/ images to compare with");
  out->camera = source->info().stereo->left;
  status = depth::StereoDepth::Create(*source->info().stereo, options, &out->stereo);
  if (!status.ok()) return Fail(status.message());
  return 0;
}

// Matches `pair` and reads its true depth; `error` gets measured minus true disparity [px] (NaN: either unknown,
// or off by more than kGrossPx, counted in `gross` when given).
int MatchedError(const LogPairs& log, const DepthSample& pair, cv::Mat* left, cv::Mat* true_depth, cv::Mat* error,
                 long* gross) {
  const auto found = log.truth.find(pair.timestamp_ns);
  if (found == log.truth.end()) return -1;
  *left = cv::imread(pair.path, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(pair.right_path, cv::IMREAD_GRAYSCALE);
  if (left->empty() || right.empty()) return Fail(pair.path + " or " + pair.right_path + ": unreadable");
  cv::Mat measured;
  Status status = log.stereo->Compute(*left, right, &measured);
  if (status.ok()) status = io::ReadDepthImage(found->second, true_depth);
  if (!status.ok()) return Fail(status.message());
  if (true_depth->size() != measured.size()) return Fail(found->second + ": not the size of the left image");
  const double fb = log.stereo->focal_px() * log.stereo->baseline_m();
  error->create(measured.size(), CV_32F);
  for (int y = 0; y < measured.rows; ++y) {
    for (int x = 0; x < measured.cols; ++x) {
      const float z = measured.at<float>(y, x), z_true = true_depth->at<float>(y, x);
      float& e = error->at<float>(y, x);
      e = std::numeric_limits<float>::quiet_NaN();
      if (z <= 0.0f || z_true <= 0.0f) continue;
      const double d = fb / z - fb / z_true;
      if (std::abs(d) > kGrossPx) {
        if (gross != nullptr) ++*gross;
        continue;
      }
      e = static_cast<float>(d);
    }
  }
  return 0;
}

int Log(const std::string& log_path, int step, const depth::StereoOptions& options) {
  LogPairs log;
  if (const int failed = ReadLog(log_path, options, &log)) return failed;
  const double fb = log.stereo->focal_px() * log.stereo->baseline_m();
  Errors errors;
  for (std::size_t i = 0; i < log.pairs.size(); i += step) {
    cv::Mat left, true_depth, error;
    const int result = MatchedError(log, log.pairs[i], &left, &true_depth, &error, &errors.gross);
    if (result < 0) continue;
    if (result > 0) return result;
    const cv::Mat deviation = LocalDeviation(left);
    for (int y = 0; y < error.rows; ++y) {
      for (int x = 0; x < error.cols; ++x) {
        const float e = error.at<float>(y, x), z_true = true_depth.at<float>(y, x);
        if (std::isnan(e)) continue;
        errors.all.Add(e);
        errors.by_depth[static_cast<int>(z_true)].Add(e);
        errors.by_texture[std::min(20, static_cast<int>(deviation.at<float>(y, x)))].Add(e);
        const double d_true = fb / z_true;
        if (z_true >= kFractionBeyondM)
          errors.by_fraction[static_cast<int>(10.0 * (d_true - std::floor(d_true)))].Add(e);
      }
    }
  }
  Print(errors, true);
  return 0;
}

// How much of the matching error frames share (depth.stereo.fuse_shared_variance): every `step`-th pair is matched,
// and each point of a lattice 8 px apart, at least kSharedBeyondM deep, is followed into the kSharedFrames pairs
// before (with the log's poses and true depth; the same surface: true depths within 5 %). Prints the correlation of
// the errors at each lag, and for points seen by all, var(mean) / var(one) = shared + (1 - shared) / n solved for
// the shared share.
int Shared(const std::string& log_path, int step, const depth::StereoOptions& options) {
  constexpr int kSharedFrames = 4;  // depth.stereo.fuse_frames' choice
  constexpr float kSharedBeyondM = 8.0f;
  constexpr int kLatticePx = 8;
  LogPairs log;
  if (const int failed = ReadLog(log_path, options, &log)) return failed;
  struct Seen {
    cv::Mat true_depth, error;
    CameraPoseSample pose;
  };
  std::vector<Seen> seen;
  struct Products {
    double xy = 0.0, xx = 0.0, yy = 0.0;
    long count = 0;
  } lags[kSharedFrames + 1];
  Mean one, mean_of_all;
  const CameraIntrinsics& camera = log.camera;
  for (std::size_t i = 0; i < log.pairs.size(); i += step) {
    const DepthSample& pair = log.pairs[i];
    if (!pair.pose) return Fail(pair.path + ": no pose (the log needs state_groundtruth_estimate0/)");
    Seen now;
    cv::Mat left;
    const int result = MatchedError(log, pair, &left, &now.true_depth, &now.error, nullptr);
    if (result < 0) continue;
    if (result > 0) return result;
    now.pose = *pair.pose;
    seen.push_back(std::move(now));
    const int k = static_cast<int>(seen.size()) - 1;
    if (k < kSharedFrames) continue;
    const Seen& current = seen[k];
    for (int y = kLatticePx / 2; y < current.error.rows; y += kLatticePx) {
      for (int x = kLatticePx / 2; x < current.error.cols; x += kLatticePx) {
        const float z = current.true_depth.at<float>(y, x), e = current.error.at<float>(y, x);
        if (!(z >= kSharedBeyondM) || std::isnan(e)) continue;
        const Eigen::Vector3d world =
            current.pose.ToWorld(Eigen::Vector3d(z * (x - camera.cx) / camera.fx, z * (y - camera.cy) / camera.fy, z));
        double sum = e;
        int views = 1;
        for (int lag = 1; lag <= kSharedFrames; ++lag, ++views) {
          const Seen& before = seen[k - lag];
          const Eigen::Vector3d p = before.pose.ToCamera(world);
          if (p.z() <= 0.0) break;
          const long u = std::lround(camera.fx * p.x() / p.z() + camera.cx);
          const long v = std::lround(camera.fy * p.y() / p.z() + camera.cy);
          if (u < 0 || v < 0 || u >= before.error.cols || v >= before.error.rows) break;
          const float other = before.error.at<float>(v, u);
          if (std::abs(before.true_depth.at<float>(v, u) - p.z()) > 0.05 * p.z() || std::isnan(other)) break;
          lags[lag].xy += e * other, lags[lag].xx += e * e, lags[lag].yy += other * other, ++lags[lag].count;
          sum += other;
        }
        if (views != kSharedFrames + 1) continue;
        one.Add(e);
        mean_of_all.Add(sum / views);
      }
    }
  }
  for (int lag = 1; lag <= kSharedFrames; ++lag) {
    const Products& p = lags[lag];
    std::printf("lag %d: %ld points, correlation %.3f\n", lag, p.count, p.xy / std::sqrt(std::max(1e-12, p.xx * p.yy)));
  }
  if (one.count == 0) return Fail("no point was seen by " + std::to_string(kSharedFrames + 1) + " pairs");
  const double n = kSharedFrames + 1, ratio = mean_of_all.squares / one.squares;
  std::printf("seen by all %d: %ld points, rms one %.3f px, rms of the mean %.3f px; var ratio %.3f => shared %.3f\n",
              kSharedFrames + 1, one.count, std::sqrt(one.squares / one.count),
              std::sqrt(mean_of_all.squares / one.count), ratio, (ratio - 1.0 / n) / (1.0 - 1.0 / n));
  return 0;
}

int Middlebury(const std::string& left_path, const std::string& right_path, const std::string& truth_path,
               int num_disparities, depth::StereoOptions options) {
  const cv::Mat left = cv::imread(left_path, cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(right_path, cv::IMREAD_GRAYSCALE);
  const cv::Mat truth = cv::imread(truth_path, cv::IMREAD_GRAYSCALE);
  if (left.empty() || right.empty() || truth.empty()) return Fail("one of the three images is missing or unreadable");
  if (left.size() != right.size() || left.size() != truth.size()) return Fail("the three images differ in size");
  options.num_disparities = num_disparities;
  std::string why;
  if (!options.IsValid(&why)) return Fail(why);
  cv::Mat disparity;
  depth::ComputeDisparity(left, right, options, &disparity);
  Errors errors;
  for (int y = 0; y < truth.rows; ++y) {
    for (int x = 0; x < truth.cols; ++x) {
      const int t = truth.at<std::uint8_t>(y, x);
      const float d = disparity.at<float>(y, x);
      if (t == 0 || d < 0.0f) continue;
      const double e = d - t;
      if (std::abs(e) > kGrossPx) {
        ++errors.gross;
        continue;
      }
      errors.all.Add(e);
    }
  }
  Print(errors, false);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string usage =
      "usage: stereo_error [--cancel-locking] LOG [STEP]\n"
      "       stereo_error [--cancel-locking] --shared LOG [STEP]\n"
      "       stereo_error [--cancel-locking] --middlebury LEFT RIGHT TRUTH NUM_DISPARITIES\n";
  depth::StereoOptions options;
  if (argc > 1 && std::string(argv[1]) == "--cancel-locking") {
    options.cancel_pixel_locking = true;
    --argc, ++argv;
  }
  if (argc == 6 && std::string(argv[1]) == "--middlebury") {
    return Middlebury(argv[2], argv[3], argv[4], std::atoi(argv[5]), options);
  }
  if ((argc == 3 || argc == 4) && std::string(argv[1]) == "--shared") {
    const int step = argc == 4 ? std::atoi(argv[3]) : 6;
    if (step < 1) return Fail(std::string("STEP must be a whole number of at least 1, not '") + argv[3] + "'");
    return Shared(argv[2], step, options);
  }
  if (argc == 2 || argc == 3) {
    const int step = argc == 3 ? std::atoi(argv[2]) : 60;
    if (step < 1) return Fail(std::string("STEP must be a whole number of at least 1, not '") + argv[2] + "'");
    return Log(argv[1], step, options);
  }
  std::fputs(usage.c_str(), stderr);
  return 2;
}
