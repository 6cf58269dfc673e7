// Plane geometry the simulator's stages share (renderer.cc, objects.cc).
#pragma once

#include <Eigen/Core>

namespace patrolmap::sim {

// The z component of the cross product of two vectors in the ground plane.
inline double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace patrolmap::sim
