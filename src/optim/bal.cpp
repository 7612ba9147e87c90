#include "orbis/optim/bal.hpp"

namespace orbis::optim {

BalBundleProblem makeBalProblem(const BalProblem& bal, double huberDelta) {
  BalBundleProblem problem;
  for (const auto& camera : bal.cameras) problem.addPose(camera);
  for (const auto& point : bal.points) problem.addPoint(point);
  const double delta2 = huberDelta * huberDelta;
  for (const auto& o : bal.observations) {
    problem.add(BalReprojection{{o.x, o.y}}, o.camera, o.point, 1.0, delta2);
  }
  return problem;
}

SolverSummary solveBal(BalProblem& bal, const SolverOptions& options, double huberDelta) {
  BalBundleProblem problem = makeBalProblem(bal, huberDelta);
  const SolverSummary summary = problem.solve(options);
  for (std::size_t i = 0; i < bal.cameras.size(); ++i) bal.cameras[i] = problem.pose(static_cast<int>(i));
  for (std::size_t l = 0; l < bal.points.size(); ++l) bal.points[l] = problem.point(static_cast<int>(l));
  return summary;
}

}  // namespace orbis::optim
