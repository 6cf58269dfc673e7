#include "patrolmap/sim/route.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <opencv2/core.hpp>

#include "patrolmap/core/csv.h"

namespace patrolmap::sim {
namespace {

constexpr double kTableStep = 0.01;  // time step of the arc-length table [s]

// One piece of the ground path: a straight line or a circular arc.
struct Piece {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  double heading = 0.0;    // at the start [rad]
  double curvature = 0.0;  // 1/m, positive turning left
  double length = 0.0;
};

Eigen::Vector2d Direction(double heading) { return {std::cos(heading), std::sin(heading)}; }

// Position and heading after `s` metres along a piece.
void Advance(const Piece& piece, double s, Eigen::Vector2d* position, double* heading) {
  *heading = piece.heading + piece.curvature * s;
  if (std::abs(piece.curvature) < 1e-12) {
    *position = piece.start + s * Direction(piece.heading);
    return;
  }
  const double r = 1.0 / piece.curvature;
  const Eigen::Vector2d centre = piece.start + r * Direction(piece.heading + M_PI / 2);
  *position = centre - r * Direction(*heading + M_PI / 2);
}

double SignedTurn(const Eigen::Vector2d& in, const Eigen::Vector2d& out) {
  return std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out));
}

std::vector<Eigen::Vector2d> DistinctPoints(const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> distinct;
  for (const Eigen::Vector2d& point : points) {
    if (distinct.empty() || (point - distinct.back()).norm() > 1e-6) distinct.push_back(point);
  }
  return distinct;
}

// Straight legs with each interior corner replaced by a tangent arc of radius r
// (smaller where a leg is too short for it).
std::vector<Piece> BuildPieces(const std::vector<Eigen::Vector2d>& points, double radius) {
  std::vector<Piece> pieces;
  Eigen::Vector2d cursor = points.front();
  for (std::size_t i = 1; i < points.size(); ++i) {
    const Eigen::Vector2d leg = points[i] - points[i - 1];
    const double heading = std::atan2(leg.y(), leg.x());
    double end_cut = 0.0, turn = 0.0, r = 0.0;
    if (i + 1 < points.size()) {
      const Eigen::Vector2d next = points[i + 1] - points[i];
      turn = SignedTurn(leg, next);
      const double limit = 0.5 * std::min(leg.norm(), next.norm());
      r = std::min(radius, limit / std::max(std::tan(std::abs(turn) / 2), 1e-9));
      end_cut = r * std::tan(std::abs(turn) / 2);
    }
    const double straight = (points[i] - cursor).norm() - end_cut;
    if (straight > 1e-9) pieces.push_back({cursor, heading, 0.0, straight});
    cursor += straight * Direction(heading);
    if (std::abs(turn) > 1e-9 && r > 1e-9) {
      Piece arc{cursor, heading, (turn > 0 ? 1.0 : -1.0) / r, r * std::abs(turn)};
      double end_heading;
      Advance(arc, arc.length, &cursor, &end_heading);
      pieces.push_back(arc);
    }
  }
  return pieces;
}

// Smooth seeded speed factor 1 + jitter * f(t), |f| <= 1, with its derivative.
struct SpeedProfile {
  double jitter = 0.0;
  double frequency[3] = {0.0, 0.0, 0.0};
  double phase[3] = {0.0, 0.0, 0.0};
  double Factor(double t) const {
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += std::sin(2 * M_PI * frequency[i] * t + phase[i]) / 3.0;
    return 1.0 + jitter * sum;
  }
  double Derivative(double t) const {
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += 2 * M_PI * frequency[i] * std::cos(2 * M_PI * frequency[i] * t + phase[i]) / 3.0;
    return jitter * sum;
  }
};

// Altitude with smooth steps: each change of `size` metres takes 2 s (smoothstep).
struct AltitudeProfile {
  double base = 3.0;
  std::vector<double> starts;
  std::vector<double> sizes;
  static constexpr double kRise = 2.0;
  void At(double t, double* z, double* rate, double* acceleration) const {
    *z = base, *rate = 0.0, *acceleration = 0.0;
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const double u = std::clamp((t - starts[i]) / kRise, 0.0, 1.0);
      const bool moving = u > 0.0 && u < 1.0;
      *z += sizes[i] * u * u * (3 - 2 * u);
      if (moving) *rate += sizes[i] * 6 * u * (1 - u) / kRise;
      if (moving) *acceleration += sizes[i] * (6 - 12 * u) / (kRise * kRise);
    }
  }
};

// Everything a trajectory query needs; shared by the copies of the std::function.
struct FlownRoute {
  std::vector<Piece> pieces;
  std::vector<double> piece_start;  // arc length where each piece begins
  std::vector<double> distance;     // arc length at t = k * kTableStep
  double speed = 0.0;
  SpeedProfile profile;
  AltitudeProfile altitude;

  double DistanceAt(double t) const {
    const double k = std::clamp(t / kTableStep, 0.0, static_cast<double>(distance.size() - 1));
    const std::size_t i = std::min(static_cast<std::size_t>(k), distance.size() - 2);
    return distance[i] + (k - i) * (distance[i + 1] - distance[i]);
  }

  PlatformState At(double t) const {
    const double s = DistanceAt(t);
    std::size_t index = std::upper_bound(piece_start.begin(), piece_start.end(), s) - piece_start.begin();
    index = index == 0 ? 0 : index - 1;
    const Piece& piece = pieces[index];
    Eigen::Vector2d position;
    double heading;
    Advance(piece, std::min(s - piece_start[index], piece.length), &position, &heading);
    const double v = speed * profile.Factor(t), dv = speed * profile.Derivative(t);
    double z, climb_speed, climb_acceleration;
    altitude.At(t, &z, &climb_speed, &climb_acceleration);
    PlatformState state;
    state.position = Eigen::Vector3d(position.x(), position.y(), z);
    state.heading = heading;
    state.yaw_rate = piece.curvature * v;
    const Eigen::Vector2d forward = Direction(heading), left = Direction(heading + M_PI / 2);
    state.velocity << v * forward, climb_speed;
    state.acceleration << dv * forward + v * v * piece.curvature * left, climb_acceleration;
    return state;
  }
};

}  // namespace

double PathLength(const Route& route, double turn_radius_m) {
  const std::vector<Eigen::Vector2d> points = DistinctPoints(route.waypoints);
  if (points.size() < 2) return 0.0;
  double length = 0.0;
  for (const Piece& piece : BuildPieces(points, turn_radius_m)) length += piece.length;
  return length;
}

Status FlyRoute(const Route& route, const RouteOptions& options, SimulatedFlight* flight) {
  const std::vector<Eigen::Vector2d> points = DistinctPoints(route.waypoints);
  if (points.size() < 2) return Status::InvalidArgument("route '" + route.name + "' needs two distinct waypoints");
  if (!(options.speed_mps > 0.0)) return Status::InvalidArgument("route speed must be positive");
  auto flown = std::make_shared<FlownRoute>();
  flown->pieces = BuildPieces(points, options.turn_radius_m);
  double total = 0.0;
  for (const Piece& piece : flown->pieces) flown->piece_start.push_back(total), total += piece.length;
  flown->speed = options.speed_mps;
  cv::RNG rng(options.seed * 2654435761u + 11u);
  flown->profile.jitter = std::clamp(options.speed_jitter, 0.0, 0.9);
  for (int i = 0; i < 3; ++i) {
    flown->profile.frequency[i] = rng.uniform(0.02, 0.15);
    flown->profile.phase[i] = rng.uniform(0.0, 2 * M_PI);
  }
  // Distance flown against time, integrated on a fine grid until the path ends.
  flown->distance.push_back(0.0);
  for (double t = 0.0; flown->distance.back() < total; t += kTableStep) {
    flown->distance.push_back(flown->distance.back() + kTableStep * options.speed_mps * flown->profile.Factor(t));
  }
  const double duration = (flown->distance.size() - 1) * kTableStep;
  flown->altitude.base = options.altitude_m;
  for (int i = 0; i < options.altitude_changes; ++i) {
    flown->altitude.starts.push_back(rng.uniform(0.1, 0.85) * duration);
    flown->altitude.sizes.push_back(rng.uniform(0, 2) == 0 ? options.altitude_change_m : -options.altitude_change_m);
  }
  flight->duration_s = duration - kTableStep;
  flight->trajectory = [flown](double t) { return flown->At(t); };
  return Status::Ok();
}

namespace {

// Waypoints and routes beyond these are no simulated patrol's: a flight of 1e9 m would render for days.
constexpr double kMaxWaypointDistanceM = 10000.0;
constexpr double kMaxRouteLengthM = 50000.0;

double RouteLength(const std::vector<Eigen::Vector2d>& waypoints) {
  double length = 0.0;
  for (std::size_t k = 1; k < waypoints.size(); ++k) length += (waypoints[k] - waypoints[k - 1]).norm();
  return length;
}

}  // namespace

Status ReadWaypoints(const std::string& path, Route* route) {
  CsvReader csv;
  PATROLMAP_RETURN_IF_ERROR(csv.Open(path));
  route->name = path;
  route->waypoints.clear();
  std::vector<std::string_view> fields;
  Status status;
  bool first = true;
  while ((status = csv.NextRow(&fields)).ok()) {
    if (fields.size() < 2) return csv.Error("expected x,y");
    const bool header = first && fields[0] == "x" && fields[1] == "y";  // a header row is allowed
    first = false;
    if (header) continue;
    Eigen::Vector2d point;
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[0], "x [m]", &point.x()));
    PATROLMAP_RETURN_IF_ERROR(csv.ParseDouble(fields[1], "y [m]", &point.y()));
    if (!(std::abs(point.x()) <= kMaxWaypointDistanceM && std::abs(point.y()) <= kMaxWaypointDistanceM)) {
      return csv.Error("a waypoint lies beyond " + std::to_string(static_cast<int>(kMaxWaypointDistanceM)) +
                       " m of the origin: the simulated village is a few hundred metres across");
    }
    route->waypoints.push_back(point);
  }
  if (!status.end_of_stream()) return status;
  const double length = RouteLength(route->waypoints);
  if (length > kMaxRouteLengthM) {
    return Status::InvalidArgument(path + ": the route is " + std::to_string(length / 1000.0) +
                                   " km long; a simulated flight covers at most " +
                                   std::to_string(static_cast<int>(kMaxRouteLengthM / 1000.0)) + " km");
  }
  if (DistinctPoints(route->waypoints).size() < 2)
    return Status::DataLoss(path + ": a route needs two distinct waypoints");
  return Status::Ok();
}

}  // namespace patrolmap::sim
