// Options of the key-location (flow) stage, paper 002 §III-A. Defaults are the
// paper's Table I and its frame handling; config/default.yaml mirrors these
// structs one to one (section "flow").
#pragma once

#include <string>

namespace patrolmap::flow {

// Which frames the stage looks at, and at what size (paper 002 §IV: every 5th
// frame of a 752x480, 30 fps camera, downscaled to 376x240). The rate is in
// time, not frames, so a 10 Hz car log, a 20 Hz EuRoC flight and a 30 Hz video
// behave alike: every step-th frame is processed, step = round(log rate /
// rate_hz), at least 1 (FrameTiming).
struct FrameOptions {
  double rate_hz = 6.0;  // processed frames per second (paper: 30 fps / 5) [Hz]
  double scale = 0.5;    // resize factor applied before edge detection, in [0.05, 1]
};

// Canny edge pixels that seed the tracker, capped and spread over the image.
struct EdgeOptions {
  double canny_low = 50.0;    // Canny hysteresis low threshold [grey levels]
  double canny_high = 150.0;  // Canny hysteresis high threshold [grey levels]
  int max_points = 600;       // cap on tracked edge pixels per frame
  int grid_columns = 8;       // the cap is shared evenly by grid_columns x grid_rows cells
  int grid_rows = 5;
  int border = 8;  // ignore edge pixels this close to the image border [pixels]
};

// Pyramidal Lucas-Kanade tracking of the edge pixels into the next processed frame.
struct TrackerOptions {
  int window_size = 11;               // LK window side [pixels, at processing scale]
  int pyramid_levels = 3;             // extra pyramid levels above the base image
  int max_iterations = 10;            // LK iteration cap per level
  double epsilon = 0.03;              // LK convergence threshold [pixels]
  double min_eigen_threshold = 1e-3;  // reject points with weaker gradient structure
  // Start each point's search from the median flow of its edge-grid cell in the
  // previous processed frame (else from zero). Keeps LK from locking onto a
  // period of repetitive texture (brick, windows) when motion is large.
  bool predict_from_previous = true;
  // Track each point back from where it was found and drop it when it lands
  // farther than this from its start [pixels]; 0 turns the check off (it costs
  // a second LK pass).
  double max_forward_backward_px = 0.0;
};

// Hysteresis voting in the polar (theta, r) domain (equations 1-2, Table I).
struct VotingOptions {
  int theta_bins = 36;           // direction cells over (-pi, pi]
  double r_bin_fraction = 0.02;  // r cell width as a fraction of image width
  int accept = 3;                // a cell is accepted once its vote reaches this (Table I)
  int reject = 2;                // an accepted cell is dropped when its vote falls under this (Table I)
  int max_votes = 3;             // vote ceiling: +1 per frame observed, -1 per frame missed
};

enum class ResponseQuantity {
  kLength,         // mean flow vector length: the paper's text ("mean vector lengths")
  kLineParameter,  // mean r of equation 2, r = x1 cos(theta) + y1 sin(theta): the paper's formula
};

// Scene-flow response, equation 3: the mean over accepted vectors. Units:
// kLength in image widths per second (independent of resolution and of the
// frame step), kLineParameter in image widths (r is a position, not a rate).
struct ResponseOptions {
  ResponseQuantity quantity = ResponseQuantity::kLength;
  bool derotate_with_imu = true;     // subtract gyro-predicted rotational flow when imu0 exists
  bool normalise_by_speed = false;   // scale by reference_speed / known speed when the log has it
  double reference_speed_mps = 2.0;  // speed at which normalised and raw responses agree [m/s]
  double min_speed_mps = 0.5;        // speeds below this are clamped (hovering) [m/s]
};

enum class SmoothingMode {
  kCentered,  // offline: window centred on the sample, no lag, results half a window late
  kCausal,    // onboard: window ends at the sample; delays the signal by (window-1)/2 frames
};

// Fixed-width window smoothing in time (Table I: 30 processed frames, which at
// the paper's 6 processed frames per second is 5 s).
struct SmoothingOptions {
  double window_s = 5.0;  // window width [s]; in processed frames: FrameTiming
  SmoothingMode mode = SmoothingMode::kCentered;
};

// Peaks and valleys of the smoothed response (Table I).
struct ExtremumOptions {
  double min_change = 0.02;  // an extremum must differ this much from the previous one [response units]
  double min_time_s = 2.0;   // and lie this long after the previous key location [s]
};

struct KeyLocationOptions {
  FrameOptions frames;
  EdgeOptions edges;
  TrackerOptions tracker;
  VotingOptions voting;
  ResponseOptions response;
  SmoothingOptions smoothing;
  ExtremumOptions extrema;

  // True when every field is in range; otherwise `error` names the first bad field.
  bool IsValid(std::string* error) const;
};

// The stage's durations in frames for a log of a given rate.
struct FrameTiming {
  int step = 5;     // process every step-th frame of the log
  int window = 30;  // smoothing window [processed frames]
  double processed_rate_hz = 6.0;
};

// `frame_rate_hz` is the log's nominal rate; 0 (unknown) processes every frame
// and takes rate_hz as the rate of those frames.
FrameTiming ResolveFrameTiming(const KeyLocationOptions& options, double frame_rate_hz);

const char* ToString(ResponseQuantity quantity);
const char* ToString(SmoothingMode mode);
bool ParseResponseQuantity(const std::string& text, ResponseQuantity* quantity);
bool ParseSmoothingMode(const std::string& text, SmoothingMode* mode);

}  // namespace patrolmap::flow
