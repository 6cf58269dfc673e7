// A 2D layout of the topological map for pictures and exports (the paper's
// Fig. 3(d) and 5): a Ceres pose graph over node poses (x, y, heading).
// Odometry edges join consecutive nodes of a flight with a scaleless step (the
// time between them times a constant speed, as the paper assumes) turned by
// the IMU yaw change; loop-closure edges pull revisits together under a robust
// (Cauchy) loss so that a false closure cannot fold the map. Scaleless: units
// are "seconds of flight".
#pragma once

#include <vector>

#include <Eigen/Core>

#include "patrolmap/core/status.h"
#include "patrolmap/graph/topo_map.h"

namespace patrolmap::graph {

// Per node: its heading from integrating the gyro [rad] (0 when unknown).
struct LayoutInput {
  std::vector<double> heading;
};

// The headings stored in the map's nodes.
LayoutInput LayoutInputOf(const TopoMap& map);

struct LayoutOptions {
  double heading_weight = 10.0;      // a radian of heading error costs as much as this many layout units
  double loop_closure_weight = 1.0;  // strength of a loop closure relative to one odometry step
  double robust_scale = 1.0;         // Cauchy loss scale for loop closures [layout units]
  int max_iterations = 100;
};

// Writes KeyFrameNode::layout of every node. The first node of the first flight
// stays at the origin facing +x; each further flight starts where its first
// loop closure puts it (or beside the earlier flights when it has none).
Status LayoutMap(const LayoutInput& input, const LayoutOptions& options, TopoMap* map);

// Odometry residual between poses a = (x, y, heading) and b: the step d and the
// turn t seen from a, the heading row scaled by w. Exposed for the Jacobian check.
// r = [R(-heading_a) (p_b - p_a) - d ; w * wrap(heading_b - heading_a - t)]
void OdometryResidual(const double* a, const double* b, const Eigen::Vector2d& step, double turn, double heading_weight,
                      double* residual, double* jacobian_a, double* jacobian_b);

}  // namespace patrolmap::graph
