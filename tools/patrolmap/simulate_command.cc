// patrolmap simulate --route double-loop|inner-loop|l-shape|street|WAYPOINTS.csv --seed N --out DIR
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "commands.h"
#include "common.h"
#include "patrolmap/sim/flight.h"
#include "patrolmap/sim/route.h"
#include "patrolmap/sim/village.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

struct SimulateArguments {
  std::string route = "double-loop";
  std::string out;
  std::uint32_t seed = 1;
  std::string resolution = "752x480";
  double mount_deg = 90.0;
  double speed_mps = 0.0;  // 0: the route's default (street 2.5, village 1.3)
  bool plain_lighting = false;
  int flights = 1;
  int first_flight = 1;  // number of the first flight written (earlier ones only advance the object changes)
  int objects = 12;
  sim::ChangeSpec changes;
  sim::LogOptions log;
  sim::RouteOptions flight;
  sim::StreetOptions street;
  std::vector<double> gps_origin;  // latitude, longitude [deg], altitude [m]; empty: LogOptions' default
};

Status ParseResolution(const std::string& text, int* width, int* height) {
  constexpr int kMaxSide = 8192;  // an 8K frame; larger renders run out of memory before they end
  if (std::sscanf(text.c_str(), "%dx%d", width, height) != 2 || *width < 32 || *height < 24 || *width > kMaxSide ||
      *height > kMaxSide) {
    return Status::InvalidArgument("--resolution must look like 752x480, from 32x24 to " + std::to_string(kMaxSide) +
                                   "x" + std::to_string(kMaxSide) + ", got '" + text + "'");
  }
  return Status::Ok();
}

// The world and flight path of flight `number` (1-based) of a series; objects are added by the caller.
Status BuildFlight(const SimulateArguments& arguments, int number, sim::SimulatedFlight* flight) {
  if (arguments.route == "street") {
    sim::StreetOptions street = arguments.street;
    street.seed = arguments.seed;
    street.mount_angle_deg = arguments.mount_deg;
    if (arguments.speed_mps > 0.0) street.speed_mps = arguments.speed_mps;
    *flight = sim::MakeStreetFlight(street);
    return Status::Ok();
  }
  sim::Route route;
  const bool preset = arguments.route.find('.') == std::string::npos && arguments.route.find('/') == std::string::npos;
  PATROLMAP_RETURN_IF_ERROR(preset ? sim::RoutePreset(arguments.route, &route)
                                   : sim::ReadWaypoints(arguments.route, &route));
  sim::Village village = sim::MakeVillage({arguments.seed});
  flight->scene = std::move(village.scene);
  flight->mount_angle = arguments.mount_deg * M_PI / 180.0;
  sim::RouteOptions options = arguments.flight;
  options.seed = arguments.seed * 100u + static_cast<std::uint32_t>(number);
  if (arguments.speed_mps > 0.0) options.speed_mps = arguments.speed_mps;
  flight->flight_id = route.name;
  return sim::FlyRoute(route, options, flight);
}

std::string FlightFolder(const SimulateArguments& arguments, int number) {
  if (arguments.flights == arguments.first_flight) return arguments.out;
  return arguments.out + "/flight_" + std::to_string(number);
}

// The objects of flight `number`: placed for the first, changed from the previous one after.
std::vector<sim::WorldObject> NextObjects(const SimulateArguments& arguments, int number,
                                          const std::vector<sim::WorldObject>& previous,
                                          std::vector<sim::ObjectChange>* changes) {
  changes->clear();
  if (arguments.route == "street" || arguments.objects == 0) return {};
  if (number == 1) return sim::PlaceObjects(arguments.objects, arguments.seed);
  return sim::ChangeObjects(previous, arguments.changes, arguments.seed * 1000u + static_cast<std::uint32_t>(number),
                            changes);
}

Status WriteFlight(const SimulateArguments& arguments, int number, std::vector<sim::WorldObject>* objects) {
  sim::SimulatedFlight flight;
  int width = 0, height = 0;
  PATROLMAP_RETURN_IF_ERROR(ParseResolution(arguments.resolution, &width, &height));
  PATROLMAP_RETURN_IF_ERROR(BuildFlight(arguments, number, &flight));
  flight.flight_id +=
      "-" + std::to_string(arguments.seed) + (arguments.flights > 1 ? "-f" + std::to_string(number) : "");
  flight.camera = flight.camera.Scaled(static_cast<double>(width) / flight.camera.width);
  flight.camera.height = height;
  if (!arguments.plain_lighting) flight.lighting = sim::DrawLighting(arguments.seed, number);
  flight.objects = NextObjects(arguments, number, *objects, &flight.changes);
  *objects = flight.objects;
  if (number < arguments.first_flight) return Status::Ok();  // only its objects matter for later flights
  sim::AddObjects(flight.objects, &flight.scene);
  const std::string folder = FlightFolder(arguments, number);
  Progress progress("simulate");
  PATROLMAP_RETURN_IF_ERROR(sim::WriteEurocLog(flight, folder, arguments.log,
                                               [&progress](int done, int total) { progress.Update(done, total); }));
  std::printf("%s: %d frames at %.3g Hz (%.1f s), %zu objects, written to %s\n", flight.flight_id.c_str(),
              sim::WrittenFrameCount(flight, arguments.log), sim::WrittenFrameRate(flight, arguments.log),
              flight.duration_s, flight.objects.size(), folder.c_str());
  return Status::Ok();
}

// --gps-origin into the log options.
Status SetGpsOrigin(SimulateArguments* arguments) {
  if (arguments->gps_origin.empty()) return Status::Ok();
  const std::vector<double>& origin = arguments->gps_origin;
  if (!(std::abs(origin[0]) <= 90.0 && std::abs(origin[1]) <= 180.0 && std::abs(origin[2]) <= 10000.0)) {
    return Status::InvalidArgument(
        "--gps-origin: latitude must lie in [-90, 90], longitude in [-180, 180] "
        "degrees and altitude in [-10000, 10000] m");
  }
  arguments->log.gps_origin_latitude = origin[0];
  arguments->log.gps_origin_longitude = origin[1];
  arguments->log.gps_origin_altitude_m = origin[2];
  return Status::Ok();
}

int RunSimulate(SimulateArguments arguments) {
  if (arguments.first_flight > 1) arguments.flights = arguments.first_flight;
  if (const Status status = SetGpsOrigin(&arguments); !status.ok()) {
    spdlog::error("{}", status.message());
    return 2;
  }
  std::vector<sim::WorldObject> objects;
  for (int number = 1; number <= arguments.flights; ++number) {
    const Status status = WriteFlight(arguments, number, &objects);
    if (!status.ok()) {
      spdlog::error("{}", status.message());
      return status.code() == StatusCode::kInvalidArgument ? 2 : 1;
    }
  }
  return 0;
}

void AddPatrolOptions(CLI::App* app, SimulateArguments* arguments) {
  app->add_option("--flights", arguments->flights,
                  "flights of a patrol series, written to OUT/flight_1 ... (lighting, "
                  "flight path jitter and objects change between them)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app->add_option("--objects", arguments->objects, "village: movable objects (crates, barrels, vehicles) in flight 1")
      ->check(CLI::Range(0, 200))
      ->capture_default_str();
  app->add_option("--remove-fraction", arguments->changes.remove_fraction,
                  "series: share of objects removed per flight")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--move-fraction", arguments->changes.move_fraction,
                  "series: share of objects moved 2-6 m per flight")
      ->check(FiniteRange(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--added", arguments->changes.added, "series: objects added per flight")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  app->add_option("--flight-number", arguments->first_flight,
                  "write only flight N of the series (its lighting, path jitter and objects after N-1 changes) "
                  "to OUT; --flights is then raised to N")
      ->check(CLI::Range(1, 100));
  app->add_flag("--detections", arguments->log.detections, "write objects0/ from a simulated object detector");
  app->add_flag("--depth", arguments->log.depth, "write depth0/ (16-bit PNG depth along the optical axis, mm)");
  app->add_flag("--gps", arguments->log.gps,
                "write gps0/ (10 Hz) and the IMU's attitude (imu0/data.csv's columns 8-11, an AHRS): with "
                "state_groundtruth_estimate0/ moved aside, the camera poses come from them");
  app->add_option("--gps-noise", arguments->log.gps_noise_m,
                  "standard deviation of each GPS fix's east and north, twice that up [m]")
      ->check(FiniteRange(0.0, 100.0))
      ->capture_default_str();
  app->add_option("--gps-bias", arguments->log.gps_bias_m,
                  "standard deviation of an offset of all of a flight's fixes, drawn once per flight and axis "
                  "(the day's GNSS error) [m]")
      ->check(FiniteRange(0.0, 100.0))
      ->capture_default_str();
  app->add_option("--attitude-noise", arguments->log.attitude_noise_deg,
                  "standard deviation of the attitude's error about each axis, fixed per flight [deg]")
      ->check(FiniteRange(0.0, 30.0))
      ->capture_default_str();
  app->add_option("--gps-origin", arguments->gps_origin,
                  "latitude, longitude [deg] and altitude [m] of the village's origin (47.3572 8.437 480); on "
                  "a point of the 0.1-degree grid with altitude 0 (47.4 8.4 0), poses from GPS have the "
                  "simulator's world frame, so eval can score them")
      ->expected(3)
      ->type_name("LAT LON ALT");
  app->add_option("--stereo", arguments->log.stereo_baseline_m,
                  "write cam1/, a second camera BASELINE_M to the right of cam0 (a stereo pair, with its sensor.yaml)")
      ->type_name("BASELINE_M")
      ->check(FiniteRange(0.01, 10.0));
  app->add_flag("--truth-only", arguments->log.truth_only,
                "write only groundtruth/ (key locations, objects, changes) as a log of the same options holds it");
  app->add_option("--motion-blur", arguments->log.exposure_s,
                  "exposure time for motion blur [s] (each frame averages 5 renders over it; 0 = sharp)")
      ->check(FiniteRange(0.0, 0.1))
      ->capture_default_str();
  app->add_option("--frame-step", arguments->log.frame_step,
                  "write every n-th frame of the 30 Hz flight (a slower camera; each written frame is the one the "
                  "full rate has, the poses, IMU and truth are the full rate's)")
      ->check(CLI::Range(1, 300))
      ->capture_default_str();
}

void AddStreetOptions(CLI::App* app, sim::StreetOptions* street) {
  app->add_option("--walls", street->walls, "street: facades along the street")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app->add_flag("--irregular", street->irregular,
                "street: draw facade lengths, gaps, depths and heights from the seed");
  app->add_option("--yaw-wobble", street->yaw_wobble_deg, "street: heading swing amplitude [deg]")
      ->check(FiniteRange(0.0, 45.0))
      ->capture_default_str();
  app->add_option("--yaw-period", street->yaw_period_s, "street: period of the heading swing [s]")
      ->check(FiniteRange(1.0, 600.0))
      ->capture_default_str();
  app->add_option("--speed-variation", street->speed_variation, "street: speed swing as a fraction of the speed")
      ->check(FiniteRange(0.0, 0.9))
      ->capture_default_str();
  app->add_option("--speed-period", street->speed_period_s, "street: period of the speed swing [s]")
      ->check(FiniteRange(1.0, 600.0))
      ->capture_default_str();
  app->add_flag("--static", street->static_camera, "street: hover in place for 10 s (no ego-motion)");
}

void AddRouteOptions(CLI::App* app, sim::RouteOptions* flight) {
  app->add_option("--speed-jitter", flight->speed_jitter, "village: smooth speed variation, fraction of the speed")
      ->check(FiniteRange(0.0, 0.9))
      ->capture_default_str();
  app->add_option("--altitude", flight->altitude_m, "village: flight height [m]")
      ->check(FiniteRange(0.5, 30.0))
      ->capture_default_str();
  app->add_option("--altitude-changes", flight->altitude_changes,
                  "village: sudden climbs or descents during the flight")
      ->check(CLI::Range(0, 20))
      ->capture_default_str();
  app->add_option("--altitude-change", flight->altitude_change_m, "village: size of each altitude change [m]")
      ->check(FiniteRange(0.1, 10.0))
      ->capture_default_str();
  app->add_option("--turn-radius", flight->turn_radius_m, "village: radius of the turns at corners [m]")
      ->check(FiniteRange(0.5, 50.0))
      ->capture_default_str();
}

}  // namespace

Command AddSimulateCommand(CLI::App* app) {
  auto arguments = std::make_shared<SimulateArguments>();
  app->add_option("--route", arguments->route,
                  "double-loop (390 m), inner-loop (137 m), l-shape (82 m) through the village, street, or a "
                  "CSV file of x,y waypoints [m] in the village frame")
      ->capture_default_str();
  app->add_option("--seed", arguments->seed, "seed of the world, textures and flight")->capture_default_str();
  app->add_option("-o,--out", arguments->out, "folder of the EuRoC-layout log to write")->required();
  app->add_option("--resolution", arguments->resolution, "image size WxH (intrinsics scale with the width)")
      ->capture_default_str();
  app->add_option("--mount", arguments->mount_deg,
                  "camera mount: angle of the optical axis from the flight direction, towards the left [deg]")
      ->check(FiniteRange(20.0, 90.0))
      ->capture_default_str();
  app->add_option("--speed", arguments->speed_mps, "mean speed [m/s] (default: street 2.5, village 1.3)")
      ->check(FiniteRange(0.1, 50.0));
  app->add_flag("--plain-lighting", arguments->plain_lighting,
                "no sun shading, exposure change or sensor noise (default: drawn from the seed)");
  AddRouteOptions(app, &arguments->flight);
  AddPatrolOptions(app, arguments.get());
  AddStreetOptions(app, &arguments->street);
  return [arguments] { return RunSimulate(*arguments); };
}

}  // namespace patrolmap::tools
