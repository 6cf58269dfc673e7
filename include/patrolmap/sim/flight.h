// Simulated flights: a trajectory through a Scene, rendered into an EuRoC/ASL
// flight log (DESIGN.md "Flight logs") with ground truth beside it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/core/status.h"
#include "patrolmap/core/types.h"
#include "patrolmap/sim/objects.h"
#include "patrolmap/sim/renderer.h"
#include "patrolmap/sim/scene.h"

namespace patrolmap::sim {

// State of the platform (the body frame: x forward, y left, z up) at one instant.
struct PlatformState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      // world [m]
  double heading = 0.0;                                    // yaw of body x from world x [rad]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      // world [m/s]
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  // world, without gravity [m/s^2]
  double yaw_rate = 0.0;                                   // [rad/s]
};

struct SimulatedFlight {
  std::string flight_id = "sim";
  Scene scene;
  CameraIntrinsics camera{458.0, 458.0, 375.5, 239.5, 752, 480};
  double frame_rate_hz = 30.0;
  double imu_rate_hz = 200.0;
  double mount_angle = 1.5707963267948966;  // optical axis from body x towards body y (left) [rad]
  Lighting lighting;                        // of this flight (default: plain texture, no noise)
  double duration_s = 0.0;
  std::function<PlatformState(double)> trajectory;  // state at time t in [0, duration_s]
  std::vector<WorldObject> objects;                 // movable objects (already added to the scene)
  std::vector<ObjectChange> changes;                // against the previous flight of a patrol series
};

// Optional parts of a written log.
struct LogOptions {
  bool detections = false;          // objects0/data.csv from the simulated detector
  bool depth = false;               // depth0/: 16-bit PNG depth along the optical axis [mm]
  double stereo_baseline_m = 0.0;   // > 0: cam1/, a second camera this far to the right of cam0 (a stereo pair)
  bool gps = false;                 // gps0/data.csv at 10 Hz, and the IMU's attitude in imu0/data.csv
  double gps_noise_m = 1.5;         // standard deviation of each fix's east and north (twice that up) [m]
  double gps_bias_m = 0.0;          // ... of an offset drawn once per flight (each axis), shared by its fixes [m]
  double attitude_noise_deg = 0.5;  // standard deviation of the attitude's error about each axis, fixed per flight
  double exposure_s = 0.0;          // motion blur: average of 5 renders spread over this exposure time (0 = sharp)
  int frame_step = 1;               // cam0 (cam1, depth0) written every this many frames of the flight: a camera at
                                    // frame_rate_hz / frame_step; each frame as at full rate (poses, IMU, truth too)
  bool truth_only = false;          // write only groundtruth/key_locations.csv (after a change of its definition)
  DetectorOptions detector;
  double gps_origin_latitude = 47.3572;  // village origin (the paper's site is near Birmensdorf) [deg]
  double gps_origin_longitude = 8.4370;
  double gps_origin_altitude_m = 480.0;
};

// Frames a log written with `options` holds (every frame_step-th of the flight), and their rate [Hz].
int WrittenFrameCount(const SimulatedFlight& flight, const LogOptions& options);
double WrittenFrameRate(const SimulatedFlight& flight, const LogOptions& options);

// Camera pose of the platform state for the flight's mount angle.
CameraPose CameraPoseAt(const SimulatedFlight& flight, const PlatformState& state);

// Ground-truth key location: the optical axis passes from a near surface to a
// far one (opening) or back (closing) — a building edge crossing the axis —
// once the inverse depth along the axis has changed by at least 0.05 1/m since
// the previous key location (a wall seen obliquely counts when its gradual
// change adds up to that). None while the platform turns faster than
// 0.25 rad/s (the view sweeps by rotation then, not by passing buildings); one
// right after a turn when the views before and after it differ that much.
struct TruthKeyLocation {
  TimestampNs timestamp_ns = 0;
  std::int64_t frame_index = 0;
  bool opening = false;       // the view axis goes from a near surface to a far one
  Eigen::Vector2d edge;       // the edge's ground position [m]
  double depth_before = 0.0;  // view-axis depth just before and after the crossing [m]
  double depth_after = 0.0;
};

// The frames at which a wall end visible on the optical axis crosses it.
std::vector<TruthKeyLocation> KeyLocationTruth(const SimulatedFlight& flight);

// Gyro and accelerometer samples at imu_rate_hz over the whole flight, in the body frame.
std::vector<ImuSample> ImuSamples(const SimulatedFlight& flight);

// Rotation taking camera-frame vectors into the body frame for a mount angle [rad].
Eigen::Matrix3d BodyFromCamera(double mount_angle);

int FrameCount(const SimulatedFlight& flight);
TimestampNs FrameTimestamp(const SimulatedFlight& flight, int frame);

// Called after each written frame with (frames done, frames in all).
using ProgressCallback = std::function<void(int, int)>;

// Renders every frame and writes the log into `folder`: meta.yaml,
// cam0/{data.csv,data/,sensor.yaml}, imu0/{data.csv,sensor.yaml},
// state_groundtruth_estimate0/data.csv, and groundtruth/ with
// key_locations.csv, places.csv (camera position and heading per frame),
// objects.csv and changes.csv; objects0/, depth0/ and gps0/ as `options` ask.
Status WriteEurocLog(const SimulatedFlight& flight, const std::string& folder, const LogOptions& options = {},
                     const ProgressCallback& progress = {});

// A straight street: `walls` near facades of `wall_length_m` separated by gaps of
// `gap_length_m`, all `near_depth_m` from the path, with one long far facade at
// `far_depth_m` seen through the gaps. The camera looks left (90 degree mount by
// default) and flies at constant speed and height from the middle of the first
// facade to the middle of the last.
struct StreetOptions {
  int walls = 3;
  double wall_length_m = 16.0;
  double gap_length_m = 12.0;
  double near_depth_m = 5.0;
  double far_depth_m = 25.0;
  double wall_height_m = 7.0;
  double speed_mps = 2.5;
  double altitude_m = 3.0;
  bool static_camera = false;     // hover at the start instead of flying
  double mount_angle_deg = 90.0;  // optical axis from the flight direction towards the left [deg]
  // Draw each facade's length (0.6-1.5x), each gap (0.5-1.3x), each near depth
  // (0.8-1.6x) and height (0.7-1.3x) from the seed instead of using them as given.
  bool irregular = false;
  // Disturbances a hand-flown UAV shows (paper 002 §III-A names both compensations):
  double yaw_wobble_deg = 0.0;   // heading swings by this amplitude ... [deg]
  double yaw_period_s = 12.0;    // ... with this period [s]
  double speed_variation = 0.0;  // speed swings by this fraction of speed_mps ...
  double speed_period_s = 12.0;  // ... with this period [s]
  std::uint32_t seed = 1;
};

// Returns the flight; `gaps` receives each gap's [start, end] position along the street [m].
SimulatedFlight MakeStreetFlight(const StreetOptions& options, std::vector<Eigen::Vector2d>* gaps = nullptr);

}  // namespace patrolmap::sim
