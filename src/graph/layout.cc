#include "patrolmap/graph/layout.h"

#include <cmath>

#include <ceres/ceres.h>

namespace patrolmap::graph {
namespace {

double Wrap(double angle) { return std::remainder(angle, 2.0 * M_PI); }

// Analytic-Jacobian cost of one odometry edge (3 residuals, two 3-parameter poses).
class OdometryCost : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  OdometryCost(const Eigen::Vector2d& step, double turn, double heading_weight)
      : step_(step), turn_(turn), heading_weight_(heading_weight) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    OdometryResidual(parameters[0], parameters[1], step_, turn_, heading_weight_, residuals,
                     jacobians != nullptr ? jacobians[0] : nullptr, jacobians != nullptr ? jacobians[1] : nullptr);
    return true;
  }

 private:
  Eigen::Vector2d step_;
  double turn_;
  double heading_weight_;
};

// Same place: the positions of the two poses coincide.
struct LoopClosureCost {
  explicit LoopClosureCost(double weight) : weight(weight) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    residual[0] = T(weight) * (b[0] - a[0]);
    residual[1] = T(weight) * (b[1] - a[1]);
    return true;
  }
  double weight;
};

}  // namespace

void OdometryResidual(const double* a, const double* b, const Eigen::Vector2d& step, double turn, double heading_weight,
                      double* residual, double* jacobian_a, double* jacobian_b) {
  const double c = std::cos(a[2]), s = std::sin(a[2]);
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  residual[0] = c * dx + s * dy - step.x();
  residual[1] = -s * dx + c * dy - step.y();
  residual[2] = heading_weight * Wrap(b[2] - a[2] - turn);
  if (jacobian_a != nullptr) {  // row-major 3x3: d residual / d (x_a, y_a, heading_a)
    const double values[9] = {-c, -s, -s * dx + c * dy, s, -c, -c * dx - s * dy, 0, 0, -heading_weight};
    std::copy(values, values + 9, jacobian_a);
  }
  if (jacobian_b != nullptr) {
    const double values[9] = {c, s, 0, -s, c, 0, 0, 0, heading_weight};
    std::copy(values, values + 9, jacobian_b);
  }
}

LayoutInput LayoutInputOf(const TopoMap& map) {
  LayoutInput input;
  for (int i = 0; i < map.node_count(); ++i) input.heading.push_back(map.node(i).heading);
  return input;
}

Status LayoutMap(const LayoutInput& input, const LayoutOptions& options, TopoMap* map) {
  const int n = map->node_count();
  if (static_cast<int>(input.heading.size()) != n)
    return Status::InvalidArgument("layout: one heading per node needed");
  std::vector<std::array<double, 3>> poses(n, {0.0, 0.0, 0.0});
  // Initial guess: dead reckoning along each flight; each flight starts below the previous ones.
  double offset = 0.0;
  for (int i = 0; i < n; ++i) {
    const bool first = i == 0 || map->node(i - 1).flight != map->node(i).flight;
    if (first) {
      poses[i] = {0.0, offset, input.heading[i]};
      offset -= 20.0;
      continue;
    }
    const double step = NsToSeconds(map->node(i).timestamp_ns - map->node(i - 1).timestamp_ns);
    const double mean = input.heading[i - 1] + 0.5 * Wrap(input.heading[i] - input.heading[i - 1]);
    poses[i] = {poses[i - 1][0] + step * std::cos(mean), poses[i - 1][1] + step * std::sin(mean), input.heading[i]};
  }
  ceres::Problem problem;
  for (const TopoMap::Edge& edge : map->Edges()) {
    double* a = poses[edge.a].data();
    double* b = poses[edge.b].data();
    if (edge.data.kind == EdgeKind::kTraversal) {
      const double step = NsToSeconds(map->node(edge.b).timestamp_ns - map->node(edge.a).timestamp_ns);
      const double turn = Wrap(input.heading[edge.b] - input.heading[edge.a]);
      const Eigen::Vector2d local(step * std::cos(0.5 * turn), step * std::sin(0.5 * turn));
      problem.AddResidualBlock(new OdometryCost(local, turn, options.heading_weight), nullptr, a, b);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<LoopClosureCost, 2, 3, 3>(new LoopClosureCost(options.loop_closure_weight)),
          new ceres::CauchyLoss(options.robust_scale), a, b);
    }
  }
  // The first node anchors the layout (a node without edges is in no residual and needs no anchor).
  if (n > 0 && problem.HasParameterBlock(poses[0].data())) problem.SetParameterBlockConstant(poses[0].data());
  ceres::Solver::Options solver;
  solver.max_num_iterations = options.max_iterations;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.num_threads = 1;  // identical results however many cores
  ceres::Solver::Summary summary;
  if (problem.NumResidualBlocks() > 0) ceres::Solve(solver, &problem, &summary);
  for (int i = 0; i < n; ++i) map->mutable_node(i).layout = Eigen::Vector2d(poses[i][0], poses[i][1]);
  return Status::Ok();
}

}  // namespace patrolmap::graph
