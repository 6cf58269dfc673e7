// Flight trajectories along a route of ground waypoints: straight legs joined
// by circular turns, flown at a speed with smooth seeded jitter and an
// altitude with optional sudden climbs (the paper's Fig. 6 false positive).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "patrolmap/core/status.h"
#include "patrolmap/sim/flight.h"

namespace patrolmap::sim {

struct RouteOptions {
  double speed_mps = 1.3;          // mean ground speed (paper: ~375 m in 8,720 frames at 30 fps)
  double speed_jitter = 0.1;       // speed varies smoothly by up to this fraction
  double altitude_m = 3.0;         // flight height above the ground
  int altitude_changes = 0;        // sudden climbs or descents of altitude_change_m during the flight
  double altitude_change_m = 1.5;  // size of each change [m]
  double turn_radius_m = 3.0;      // radius of the arcs that round the corners
  std::uint32_t seed = 1;          // jitter phases and the times of altitude changes
};

// A route: a polyline of ground positions [m], flown from the first to the last point.
struct Route {
  std::string name;
  std::vector<Eigen::Vector2d> waypoints;
};

// Length of the flown path after rounding the corners [m].
double PathLength(const Route& route, double turn_radius_m);

// Fills the trajectory and duration of `flight` to fly `route`. Fails when the
// route has fewer than two distinct points.
Status FlyRoute(const Route& route, const RouteOptions& options, SimulatedFlight* flight);

// Reads a route from a CSV file of "x,y" lines [m] ('#' comments allowed).
Status ReadWaypoints(const std::string& path, Route* route);

}  // namespace patrolmap::sim
