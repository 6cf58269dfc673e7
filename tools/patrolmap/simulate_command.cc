// patrolmap simulate --route street --seed N --out DIR
#include <cstdio>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

#include "commands.h"
#include "patrolmap/sim/flight.h"
#include "progress.h"

namespace patrolmap::tools {
namespace {

struct SimulateArguments {
  std::string route = "street";
  std::string out;
  std::uint32_t seed = 1;
  bool static_camera = false;
  double speed_mps = 2.5;
  int walls = 3;
  double mount_deg = 90.0;
  bool irregular = false;
  double yaw_wobble_deg = 0.0;
  double speed_variation = 0.0;
  double yaw_period_s = 12.0;
  double speed_period_s = 12.0;
};

int RunSimulate(const SimulateArguments& arguments) {
  sim::StreetOptions street;
  street.seed = arguments.seed;
  street.static_camera = arguments.static_camera;
  street.speed_mps = arguments.speed_mps;
  street.walls = arguments.walls;
  street.mount_angle_deg = arguments.mount_deg;
  street.irregular = arguments.irregular;
  street.yaw_wobble_deg = arguments.yaw_wobble_deg;
  street.speed_variation = arguments.speed_variation;
  street.yaw_period_s = arguments.yaw_period_s;
  street.speed_period_s = arguments.speed_period_s;
  sim::SimulatedFlight flight = sim::MakeStreetFlight(street);
  flight.flight_id = arguments.route + "-" + std::to_string(arguments.seed);
  Status status;
  {
    Progress progress("simulate");
    status = sim::WriteEurocLog(flight, arguments.out,
                                [&progress](int done, int total) { progress.Update(done, total); });
  }
  if (!status.ok()) {
    spdlog::error("{}", status.message());
    return 1;
  }
  std::printf("%s: %d frames at %.0f Hz (%.1f s) written to %s\n", flight.flight_id.c_str(), sim::FrameCount(flight),
              flight.frame_rate_hz, flight.duration_s, arguments.out.c_str());
  return 0;
}

}  // namespace

Command AddSimulateCommand(CLI::App* app) {
  auto arguments = std::make_shared<SimulateArguments>();
  app->add_option("--route", arguments->route, "route preset")
      ->check(CLI::IsMember({"street"}))
      ->capture_default_str();
  app->add_option("--seed", arguments->seed, "seed of the textures")->capture_default_str();
  app->add_option("-o,--out", arguments->out, "folder of the EuRoC-layout log to write")->required();
  app->add_option("--speed", arguments->speed_mps, "flight speed [m/s]")->check(CLI::PositiveNumber)->capture_default_str();
  app->add_option("--walls", arguments->walls, "facades along the street")->check(CLI::Range(1, 100))->capture_default_str();
  app->add_option("--mount", arguments->mount_deg, "camera mount: angle of the optical axis from the flight "
                  "direction, towards the left [deg]")
      ->check(CLI::Range(20.0, 90.0))
      ->capture_default_str();
  app->add_flag("--irregular", arguments->irregular, "draw facade lengths, gaps, depths and heights from the seed");
  app->add_option("--yaw-wobble", arguments->yaw_wobble_deg, "heading swing amplitude [deg]")
      ->check(CLI::Range(0.0, 45.0))
      ->capture_default_str();
  app->add_option("--speed-variation", arguments->speed_variation,
                  "speed swing as a fraction of --speed")
      ->check(CLI::Range(0.0, 0.9))
      ->capture_default_str();
  app->add_option("--yaw-period", arguments->yaw_period_s, "period of the heading swing [s]")
      ->check(CLI::Range(1.0, 600.0))
      ->capture_default_str();
  app->add_option("--speed-period", arguments->speed_period_s, "period of the speed swing [s]")
      ->check(CLI::Range(1.0, 600.0))
      ->capture_default_str();
  app->add_flag("--static", arguments->static_camera, "hover in place for 10 s (no ego-motion)");
  return [arguments] { return RunSimulate(*arguments); };
}

}  // namespace patrolmap::tools
