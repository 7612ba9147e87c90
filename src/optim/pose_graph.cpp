#include "orbis/optim/pose_graph.hpp"

#include "orbis/optim/pose_graph_residuals.hpp"
#include "orbis/optim/problem.hpp"

namespace orbis::optim {

SolverSummary optimizePoseGraph(std::vector<SE3d>& cameraFromWorld, const std::vector<char>& fixed,
                                std::span<const PoseGraphEdgeSE3> edges, const SolverOptions& options) {
  Problem<SE3Manifold, Term<RelativePoseSE3>> problem;
  for (std::size_t k = 0; k < cameraFromWorld.size(); ++k) {
    problem.addPose(cameraFromWorld[k], k < fixed.size() && fixed[k]);
  }
  for (const auto& e : edges) problem.add(RelativePoseSE3{e.relative}, e.i, e.j, e.information);
  const SolverSummary summary = problem.solve(options);
  for (std::size_t k = 0; k < cameraFromWorld.size(); ++k) cameraFromWorld[k] = problem.pose(static_cast<int>(k));
  return summary;
}

}  // namespace orbis::optim
