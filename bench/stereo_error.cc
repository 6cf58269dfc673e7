// Stereo matching error against true depth (BENCHMARKS.md, "Stereo depth", session 17).
//
//   stereo_error [--cancel-locking] LOG [STEP]
//     A log with cam0/, cam1/ (and their sensor.yaml) and depth0/ of the same times, such as a simulated one
//     (`patrolmap simulate --stereo 0.5 --depth`): every STEP-th pair (default 60) is matched with the default
//     stereo options and each depth compared with depth0/'s, as disparity f * b / z.
//   stereo_error [--cancel-locking] --middlebury LEFT RIGHT TRUTH NUM_DISPARITIES
//     A rectified pair with its 8-bit true disparity (0 = unknown), matched with the defaults and that range.
//
// Prints the pixels compared, the share off by more than 3 px, and the mean and rms of the rest; for a log also
// the mean per metre of true depth, per grey level of the left image's 7x7 standard deviation and per tenth of the
// true disparity's fraction. --cancel-locking matches with depth.stereo.cancel_pixel_locking on.
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

int Log(const std::string& log, int step, const depth::StereoOptions& options) {
  std::unique_ptr<io::FrameSource> source;
  Status status = io::OpenEuroc(log, &source);
  if (!status.ok()) return Fail(status.message());
  if (!source->info().stereo) return Fail(log + ": no stereo pair (cam1/ with sensor.yaml)");
  std::map<TimestampNs, std::string> truth;  // depth0/ images by time
  std::vector<DepthSample> pairs;            // stereo pairs
  Frame frame;
  while ((status = source->Next(false, &frame)).ok()) {
    for (DepthSample& d : frame.depth) {
      if (d.stereo()) {
        pairs.push_back(std::move(d));
      } else {
        truth[d.timestamp_ns] = d.path;
      }
    }
  }
  if (!status.end_of_stream()) return Fail(status.message());
  if (truth.empty()) return Fail(log + ": no depth0/ images to compare with");
  std::unique_ptr<depth::StereoDepth> stereo;
  status = depth::StereoDepth::Create(*source->info().stereo, options, &stereo);
  if (!status.ok()) return Fail(status.message());
  const double fb = stereo->focal_px() * stereo->baseline_m();
  Errors errors;
  for (std::size_t i = 0; i < pairs.size(); i += step) {
    const DepthSample& pair = pairs[i];
    const auto found = truth.find(pair.timestamp_ns);
    if (found == truth.end()) continue;
    const cv::Mat left = cv::imread(pair.path, cv::IMREAD_GRAYSCALE);
    const cv::Mat right = cv::imread(pair.right_path, cv::IMREAD_GRAYSCALE);
    if (left.empty() || right.empty()) return Fail(pair.path + " or " + pair.right_path + ": unreadable");
    cv::Mat measured, true_depth;
    status = stereo->Compute(left, right, &measured);
    if (status.ok()) status = io::ReadDepthImage(found->second, &true_depth);
    if (!status.ok()) return Fail(status.message());
    if (true_depth.size() != measured.size()) return Fail(found->second + ": not the size of the left image");
    const cv::Mat deviation = LocalDeviation(left);
    for (int y = 0; y < measured.rows; ++y) {
      for (int x = 0; x < measured.cols; ++x) {
        const float z = measured.at<float>(y, x), z_true = true_depth.at<float>(y, x);
        if (z <= 0.0f || z_true <= 0.0f) continue;
        const double e = fb / z - fb / z_true;
        if (std::abs(e) > kGrossPx) {
          ++errors.gross;
          continue;
        }
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
      "       stereo_error [--cancel-locking] --middlebury LEFT RIGHT TRUTH NUM_DISPARITIES\n";
  depth::StereoOptions options;
  if (argc > 1 && std::string(argv[1]) == "--cancel-locking") {
    options.cancel_pixel_locking = true;
    --argc, ++argv;
  }
  if (argc == 6 && std::string(argv[1]) == "--middlebury") {
    return Middlebury(argv[2], argv[3], argv[4], std::atoi(argv[5]), options);
  }
  if (argc == 2 || argc == 3) {
    const int step = argc == 3 ? std::atoi(argv[2]) : 60;
    if (step < 1) return Fail(std::string("STEP must be a whole number of at least 1, not '") + argv[2] + "'");
    return Log(argv[1], step, options);
  }
  std::fputs(usage.c_str(), stderr);
  return 2;
}
