// The flight-log readers and the function that picks one for a path.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "patrolmap/io/frame_source.h"

namespace patrolmap::io {

// Rate taken for a log without timestamps when none is given (with a warning) [Hz].
constexpr double kAssumedFrameRateHz = 30.0;

// The topics of a ROS bag a flight is read from (--topic ROLE=NAME); an empty name takes the first topic
// of the role's type (bag.h).
struct TopicChoice {
  std::string camera, camera_info, imu, gps, pose;
  std::string depth;  // depth images (16UC1 [mm] or 32FC1 [m]); default: an image topic named "...depth..."
  std::string right;  // the right camera of a stereo pair; default: none
};

// Sets the roles of "ROLE=NAME" assignments (roles: camera, camera_info, imu, gps, pose, depth,
// right); fails naming an
// assignment without '=', an unknown role or a role given twice.
Status ParseTopicChoice(const std::vector<std::string>& assignments, TopicChoice* choice);

struct ImageFolderOptions {
  // Frame rate of image folders, printf patterns and videos [Hz] (--fps). 0: from the log's own times
  // (a times file, the file names, the video's metadata); a log without any is read at
  // kAssumedFrameRateHz with a warning. A positive rate overrides the log's times.
  double frame_rate_hz = 0.0;
  // Topics of a ROS bag.
  TopicChoice topics;
};

// Image folder: every .png/.jpg/.jpeg/.bmp/.pgm/.ppm/.tif/.tiff file of a
// folder, in natural order. Timestamps from the folder (FindImageTimes in
// image_times.h: KITTI times.txt, numeric file names) unless frame_rate_hz is
// set, else index / kAssumedFrameRateHz.
Status OpenImageFolder(const std::string& folder, const ImageFolderOptions& options,
                       std::unique_ptr<FrameSource>* source);

// printf pattern such as "flight/frame_%05d.png": indices from the first that
// exists (0 or 1) up to the first gap.
Status OpenImagePattern(const std::string& pattern, const ImageFolderOptions& options,
                        std::unique_ptr<FrameSource>* source);

// Video file through OpenCV VideoCapture; frames converted to grey.
Status OpenVideo(const std::string& path, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source);

// Camera device `device` (OpenCV VideoCapture index, /dev/videoN on Linux); frames converted to grey and
// timed by the clock from the first one; flight id "cameraN".
Status OpenCamera(int device, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source);

// EuRoC/ASL layout (DESIGN.md): <log>/cam0/data.csv and cam0/data/, optional
// cam0/sensor.yaml, imu0/data.csv (+ imu0/sensor.yaml), meta.yaml and
// state_groundtruth_estimate0/data.csv (platform speed). A top folder holding
// mav0/ (as EuRoC archives do) is accepted too. The tables are checked when
// the log is opened: malformed lines and non-monotonic timestamps fail here.
Status OpenEuroc(const std::string& folder, std::unique_ptr<FrameSource>* source);

// ROS 1 bag (.bag) or ROS 2 bag (a folder with metadata.yaml, or one of its .db3 files): bag.h.
Status OpenBag(const std::string& path, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source);

// Fails with "PATH: no such file or folder" unless `path` exists (a printf pattern: its folder), so a
// front end can name a missing log before it loads anything else.
Status CheckLogExists(const std::string& path);

// Picks the reader for `path`: a ROS bag (IsBag in bag.h), EuRoC when it holds cam0/data.csv (or
// mav0/cam0/data.csv), a printf pattern when it contains '%', an image folder
// for other folders, and a video for other files.
Status OpenLog(const std::string& path, const ImageFolderOptions& options, std::unique_ptr<FrameSource>* source);

}  // namespace patrolmap::io
