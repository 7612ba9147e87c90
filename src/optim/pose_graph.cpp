#include "orbis/optim/pose_graph.hpp"

#include "orbis/optim/pose_graph_residuals.hpp"
#include "orbis/optim/problem.hpp"

namespace orbis::optim {

namespace {

template <class Residual, class Pose, class Edge>
SolverSummary optimize(std::vector<Pose>& cameraFromWorld, const std::vector<char>& fixed,
                       std::span<const Edge> edges, const SolverOptions& options) {
  Problem<typename Residual::PoseManifold, Term<Residual>> problem;
  for (std::size_t k = 0; k < cameraFromWorld.size(); ++k) {
    problem.addPose(cameraFromWorld[k], k < fixed.size() && fixed[k]);
  }
  for (const auto& e : edges) problem.add(Residual{e.relative}, e.i, e.j, e.information);
  const SolverSummary summary = problem.solve(options);
  for (std::size_t k = 0; k < cameraFromWorld.size(); ++k) cameraFromWorld[k] = problem.pose(static_cast<int>(k));
  return summary;
}

}  // namespace

SolverSummary optimizePoseGraph(std::vector<SE3d>& cameraFromWorld, const std::vector<char>& fixed,
                                std::span<const PoseGraphEdgeSE3> edges, const SolverOptions& options) {
  return optimize<RelativePoseSE3>(cameraFromWorld, fixed, edges, options);
}

SolverSummary optimizePoseGraph(std::vector<Sim3d>& cameraFromWorld, const std::vector<char>& fixed,
                                std::span<const PoseGraphEdgeSim3> edges, const SolverOptions& options) {
  return optimize<RelativePoseSim3>(cameraFromWorld, fixed, edges, options);
}

}  // namespace orbis::optim
