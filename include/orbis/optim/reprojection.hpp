// orbis/optim/reprojection.hpp — reprojection residuals of a world point seen by a camera pose,
// generic over the camera model: 2×6×3 for a pinhole (monocular), 3×6×3 for rectified stereo and
// RGB-D (uL, v, uR), and 3×6×3 for a depth sensor's (uL, v, disparity) (DisparityReprojection).
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

// A point seen by a camera model: r = camera.project(T·X) − measurement, with analytic Jacobians
// for the pose (left update) and the point.
template <CameraModel Camera>
struct Reprojection {
  // @{
  // An SE(3) pose with a point; rows: the camera's observation size.
  using PoseManifold = SE3Manifold;
  static constexpr int kDim = Camera::kObservationDim;
  static constexpr bool kHasPoint = true;
  using Observation = Eigen::Matrix<double, kDim, 1>;
  // @}

  // The observed keypoint, (u, v) or (uL, v, uR).
  Observation measurement;
  // The camera model (not owned).
  const Camera* camera = nullptr;

  // Residual and Jacobians (either may be null).
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

// @{
// The reprojection residuals of the shipped cameras.
using MonoReprojection = Reprojection<PinholeCamera<double>>;
using StereoReprojection = Reprojection<RectifiedStereoCamera<double>>;
using RgbdReprojection = Reprojection<RgbdCamera<double>>;
// @}

// A depth sensor's observation. Its virtual right coordinate uR = uL − bf/d is the measured uL
// minus a disparity from the sensor, so uR's error is uL's error plus the sensor's: the stereo
// residual above (uL, v, uR), right for two images matched independently, would count the
// keypoint's horizontal error twice and give the depth the weight of a second keypoint (σ√2 px
// of disparity, where a Kinect measures it to a fraction of that). The rows here are the keypoint
// (uL, v) and its disparity uL − uR whitened by disparityWeight = σ(keypoint) / σ(disparity), so
// information·‖r‖² is still χ² with 3 degrees of freedom. The measurement is stored as (uL, v, uR)
// like the stereo one. Camera: any 3-D model projecting to (uL, v, uR).
template <CameraModel Camera>
struct DisparityReprojection {
  static_assert(Camera::kObservationDim == 3, "the disparity residual needs a (uL, v, uR) camera");
  // @{
  // An SE(3) pose with a point; three rows.
  using PoseManifold = SE3Manifold;
  static constexpr int kDim = 3;
  static constexpr bool kHasPoint = true;
  using Observation = Eigen::Vector3d;
  // @}

  // The observed (uL, v, uR).
  Observation measurement;
  // The camera model (not owned).
  const Camera* camera = nullptr;
  // σ(keypoint) / σ(disparity).
  double disparityWeight = 1.0;

  // Residual and Jacobians (either may be null).
  void evaluate(const SE3d& cameraFromWorld, const Eigen::Vector3d& pointWorld, Observation& r,
                Eigen::Matrix<double, 3, 6>* jPose, Eigen::Matrix<double, 3, 3>* jPoint) const {
    // The stereo residual, then its third row replaced by w·(row uL − row uR): a linear map, so
    // the Jacobians follow by the same rows.
    const Reprojection<Camera> stereo{measurement, camera};
    stereo.evaluate(cameraFromWorld, pointWorld, r, jPose, jPoint);
    r(2) = disparityWeight * (r(0) - r(2));
    if (jPose) jPose->row(2) = disparityWeight * (jPose->row(0) - jPose->row(2));
    if (jPoint) jPoint->row(2) = disparityWeight * (jPoint->row(0) - jPoint->row(2));
  }
};

// The disparity residual on a stereo camera model.
using DepthReprojection = DisparityReprojection<RectifiedStereoCamera<double>>;

// The same projection seen from the other end of a relative pose: the pose variable T is
// camera-1-from-camera-2, the point lives in camera 1, and camera 2 observes it:
// r = camera.project(T⁻¹·X) − measurement. With the left update T ← exp(δ)·T,
// T⁻¹·X = T⁻¹·exp(−δ)·X, so ∂(T⁻¹X)/∂δ = −R⁻¹·[I, −[X]×]. Loop closing's two-way relative pose
// pairs it with Reprojection (camera 1 observing camera 2's point through T).
template <CameraModel Camera>
struct InversePoseReprojection {
  // @{
  // An SE(3) pose with a point; rows: the camera's observation size.
  using PoseManifold = SE3Manifold;
  static constexpr int kDim = Camera::kObservationDim;
  static constexpr bool kHasPoint = true;
  using Observation = Eigen::Matrix<double, kDim, 1>;
  // @}

  // Camera 2's observed keypoint.
  Observation measurement;
  // The camera model (not owned).
  const Camera* camera = nullptr;

  // Residual and Jacobians (either may be null).
  void evaluate(const SE3d& T, const Eigen::Vector3d& point, Observation& r, Eigen::Matrix<double, kDim, 6>* jPose,
                Eigen::Matrix<double, kDim, 3>* jPoint) const {
    const SE3d inverse = T.inverse();
    const Eigen::Vector3d pc = inverse * point;
    r = camera->project(pc) - measurement;
    if (!jPose && !jPoint) return;
    const Eigen::Matrix<double, kDim, 3> dProjectR = camera->projectJacobian(pc) * inverse.rotationMatrix();
    if (jPose) {
      jPose->template leftCols<3>() = -dProjectR;
      jPose->template rightCols<3>().noalias() = dProjectR * SO3d::hat(point);
    }
    if (jPoint) *jPoint = dProjectR;
  }
};

// ORB-SLAM's per-observation information: σ² = scaleFactor^(2·octave), information = 1/σ².
inline double levelInformation(double scaleFactor, int octave) {
  double sigma2 = 1.0;
  const double factor2 = scaleFactor * scaleFactor;
  for (int i = 0; i < octave; ++i) sigma2 *= factor2;
  return 1.0 / sigma2;
}

}  // namespace orbis::optim
