// orbis/optim/slam_residuals.hpp — the problem type the SLAM pipeline's BAs solve.
//
// Contract: SlamProblem has SE(3) camera-from-world poses, world points, and two terms with
// Huber kernels: monocular (2-row) and stereo/RGB-D (3-row) reprojection residuals, as in
// paper Eq. (2)–(4). ObservationCameras holds the two camera models the residuals point to,
// built from the map's pinhole intrinsics and bf; it must outlive the problem.
#pragma once

#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"

namespace orbis::optim {

using SlamProblem = Problem<SE3Manifold, Term<MonoReprojection, HuberKernel>, Term<StereoReprojection, HuberKernel>>;

struct ObservationCameras {
  PinholeCamera<double> mono;
  RectifiedStereoCamera<double> stereo;

  ObservationCameras(double fx, double fy, double cx, double cy, double bf)
      : mono{fx, fy, cx, cy, 0, 0}, stereo(mono, bf > 0 ? bf / fx : 0.0, 0.0) {}
};

}  // namespace orbis::optim
