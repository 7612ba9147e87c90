// orbis/optim/pose_graph.hpp — essential-graph optimisation (paper §III-D): poses only, linked
// by relative-pose edges (spanning tree, strong covisibility, loop edges).
//
// Contract: poses are camera-from-world; an edge (i, j) carries T_ij = T_iw·T_jw⁻¹ as measured
// before the loop correction, and an isotropic information weight. Fixed poses (at least one,
// usually the loop keyframe) are never written. ORB-SLAM runs 20 LM iterations; that is the
// default here. Stereo/RGB-D maps use SE(3); monocular maps Sim(3), whose edges carry S_ij.
#pragma once

#include "orbis/geometry/se3.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/optim/solver_options.hpp"

#include <span>
#include <vector>

namespace orbis::optim {

// An SE(3) pose-graph edge: the relative motion measured between poses i and j.
struct PoseGraphEdgeSE3 {
  // @{
  // The two poses.
  int i = 0;
  int j = 0;
  // @}
  SE3d relative;  // T_ij
  // Weight of the edge's residual.
  double information = 1.0;
};

// A Sim(3) pose-graph edge (monocular loop closing's essential graph).
struct PoseGraphEdgeSim3 {
  // @{
  // The two poses.
  int i = 0;
  int j = 0;
  // @}
  Sim3d relative;  // S_ij
  // Weight of the edge's residual.
  double information = 1.0;
};

// ORB-SLAM's essential-graph optimisation settings (20 iterations).
inline SolverOptions essentialGraphOptions() {
  SolverOptions options;
  options.maxIterations = 20;
  return options;
}

// Optimises SE(3) poses (camera from world) over the edges, keeping the fixed ones.
SolverSummary optimizePoseGraph(std::vector<SE3d>& cameraFromWorld, const std::vector<char>& fixed,
                                std::span<const PoseGraphEdgeSE3> edges,
                                const SolverOptions& options = essentialGraphOptions());

// Optimises Sim(3) poses over the edges, keeping the fixed ones.
SolverSummary optimizePoseGraph(std::vector<Sim3d>& cameraFromWorld, const std::vector<char>& fixed,
                                std::span<const PoseGraphEdgeSim3> edges,
                                const SolverOptions& options = essentialGraphOptions());

}  // namespace orbis::optim
