// orbis/optim/reprojection.hpp — reprojection residuals of a world point seen by a camera pose,
// generic over the camera model: 2×6×3 for a pinhole (monocular), 3×6×3 for rectified stereo and
// RGB-D (uL, v, uR).
//
// Contract: r = camera.project(T_cw·X_w) − measurement (predicted minus observed; the sign does
// not change the cost). Jacobians are with respect to the left update exp(δ)·T_cw (SE3Manifold)
// and the world point. The residual keeps a pointer to its camera, which must outlive the problem.
// No check that the point is in front of the camera: callers build only residuals they trust, as
// ORB-SLAM does, and a point drifting behind the camera is caught by their χ² test.
#pragma once

#include "orbis/camera/camera_model.hpp"
#include "orbis/optim/lie_manifolds.hpp"

#include <Eigen/Core>

namespace orbis::optim {

template <CameraModel Camera>
struct Reprojection {
  using PoseManifold = SE3Manifold;
  static constexpr int kDim = Camera::kObservationDim;
  static constexpr bool kHasPoint = true;
  using Observation = Eigen::Matrix<double, kDim, 1>;

  Observation measurement;
  const Camera* camera = nullptr;

  void evaluate(const SE3d& cameraFromWorld, const Eigen::Vector3d& pointWorld, Observation& r,
                Eigen::Matrix<double, kDim, 6>* jPose, Eigen::Matrix<double, kDim, 3>* jPoint) const {
    const Eigen::Vector3d pc = cameraFromWorld * pointWorld;
    r = camera->project(pc) - measurement;
    if (!jPose && !jPoint) return;
    const Eigen::Matrix<double, kDim, 3> dProject = camera->projectJacobian(pc);
    if (jPose) {
      jPose->template leftCols<3>() = dProject;
      jPose->template rightCols<3>().noalias() = -dProject * SO3d::hat(pc);
    }
    if (jPoint) jPoint->noalias() = dProject * cameraFromWorld.rotationMatrix();
  }
};

using MonoReprojection = Reprojection<PinholeCamera<double>>;
using StereoReprojection = Reprojection<RectifiedStereoCamera<double>>;
using RgbdReprojection = Reprojection<RgbdCamera<double>>;

// ORB-SLAM's per-observation information: σ² = scaleFactor^(2·octave), information = 1/σ².
inline double levelInformation(double scaleFactor, int octave) {
  double sigma2 = 1.0;
  const double factor2 = scaleFactor * scaleFactor;
  for (int i = 0; i < octave; ++i) sigma2 *= factor2;
  return 1.0 / sigma2;
}

}  // namespace orbis::optim
