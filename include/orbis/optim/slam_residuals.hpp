// orbis/optim/slam_residuals.hpp — the problem type the SLAM pipeline's BAs solve.
//
// Contract: SlamProblem has SE(3) camera-from-world poses, world points, and three terms with
// Huber kernels: monocular (2-row) and stereo (3-row) reprojection residuals, as in paper
// Eq. (2)–(4), and the depth sensor's (uL, v, whitened disparity) residual (reprojection.hpp).
// ObservationCameras holds the camera models the residuals point to, built from the map's
// pinhole intrinsics, bf and disparity σ, picks the residual per keypoint, and must outlive
// the problem.
#pragma once

#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"

namespace orbis::optim {

using SlamProblem = Problem<SE3Manifold, Term<MonoReprojection, HuberKernel>, Term<StereoReprojection, HuberKernel>,
                             Term<DepthReprojection, HuberKernel>>;

struct ObservationCameras {
  PinholeCamera<double> mono;
  RectifiedStereoCamera<double> stereo;
  // σ(keypoint)/σ(disparity) of a depth sensor; 0 for a stereo pair, whose uR is measured.
  double disparityWeight = 0.0;

  // disparitySigma: a depth sensor's σ of the virtual disparity bf/d in pixels (level 0); 0 for
  // a stereo pair or a monocular camera.
  ObservationCameras(double fx, double fy, double cx, double cy, double bf, double disparitySigma = 0.0)
      : mono{fx, fy, cx, cy, 0, 0},
        stereo(mono, bf > 0 ? bf / fx : 0.0, 0.0),
        disparityWeight(disparitySigma > 0 ? 1.0 / disparitySigma : 0.0) {}

  // The residual a keypoint (u, v) with right coordinate uR (negative: none) calls for —
  // monocular, stereo or depth — added to `problem` with the keypoint level's information and
  // the Huber threshold of its χ² test. threeDof tells the caller which test applies.
  ResidualId add(SlamProblem& problem, int pose, int point, double u, double v, double uR, double information,
                 bool& threeDof) const {
    threeDof = uR >= 0;
    if (!threeDof) return problem.add(MonoReprojection{{u, v}, &mono}, pose, point, information, kChi2Mono);
    if (disparityWeight > 0)
      return problem.add(DepthReprojection{{u, v, uR}, &stereo, disparityWeight}, pose, point, information,
                         kChi2Stereo);
    return problem.add(StereoReprojection{{u, v, uR}, &stereo}, pose, point, information, kChi2Stereo);
  }
};

}  // namespace orbis::optim
