#include "orbis/tracking/pose_optimizer.hpp"

#include <limits>
#include <vector>

#include "orbis/optim/slam_residuals.hpp"

namespace orbis {

int optimizePose(Frame& frame) {
  using namespace optim;
  const MapIntrinsics& K = frame.intrinsics;
  const ObservationCameras cameras(K.fx, K.fy, K.cx, K.cy, K.bf, K.disparitySigma);
  const FrameFeatures& f = *frame.features;
  SlamProblem problem;
  const int pose = problem.addPose(frame.Tcw);
  struct Edge {
    std::size_t keypoint;
    ResidualId id;
    bool threeDof;
  };
  std::vector<Edge> edges;
  edges.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (!p) continue;
    frame.outlier[i] = 0;
    const int point = problem.addPoint(p->position(), /*fixed=*/true);
    const Keypoint& k = f.keypointsUn[i];
    const double information = f.scales.invSigma2[static_cast<std::size_t>(k.octave)];
    Edge e{i, {}, false};
    e.id = cameras.add(problem, pose, point, k.u, k.v, f.uRight[i], information, e.threeDof);
    edges.push_back(e);
  }
  if (edges.size() < 3) return 0;

  // ORB-SLAM's schedule: four rounds of 10 iterations from the initial pose, reclassifying every
  // observation by its χ² after each; the last two rounds without the robust kernel.
  SolverOptions options;
  options.maxIterations = 10;
  options.linearSolver = LinearSolverKind::DenseCholesky;
  int bad = 0;
  for (int round = 0; round < 4; ++round) {
    problem.setPose(pose, frame.Tcw);
    problem.solve(options);
    bad = 0;
    for (const Edge& e : edges) {
      const double chi2 = problem.chi2(e.id);
      const bool isOutlier = chi2 > (e.threeDof ? kChi2Stereo : kChi2Mono);
      frame.outlier[e.keypoint] = isOutlier ? 1 : 0;
      problem.setActive(e.id, !isOutlier);
      bad += isOutlier ? 1 : 0;
      if (round == 2) problem.setKernelThreshold(e.id, std::numeric_limits<double>::infinity());
    }
    if (static_cast<int>(edges.size()) - bad < 10) break;
  }
  frame.Tcw = problem.pose(pose);
  return static_cast<int>(edges.size()) - bad;
}

}  // namespace orbis
