// orbis/optim/sim3_reprojection.hpp — the two reprojection residuals of a similarity between two
// cameras, for a monocular loop (paper §III-D; ORB-SLAM's OptimizeSim3): each keyframe's map
// points, expressed in its own camera, seen by the other camera through S12.
//
// Contract: the pose variable is S12 ∈ Sim(3), camera-1-from-camera-2 with camera 2's map scale
// taken to camera 1's (q = s·R·p + t). Sim3Reprojection: the point lives in camera 2 and camera 1
// observes it, r = camera.project(S12·p) − measurement. InverseSim3Reprojection: the point lives
// in camera 1 and camera 2 observes it, r = camera.project(S12⁻¹·p) − measurement. Jacobians are
// with respect to Sim3Manifold's left update S ← exp(δ)·S, δ = (υ, ω, σ), and the point; points
// are usually held fixed (their Jacobians serve the generic checks). No in-front check, as in
// reprojection.hpp: callers build residuals they trust and gate them by χ².
#pragma once

#include "orbis/camera/camera_model.hpp"
#include "orbis/optim/lie_manifolds.hpp"

#include <Eigen/Core>

namespace orbis::optim {

// Loop closing's Sim(3) fit: a point of keyframe 2 seen by keyframe 1 through S12.
template <CameraModel Camera>
struct Sim3Reprojection {
  // @{
  // A Sim(3) pose with a point; rows: the camera's observation size.
  using PoseManifold = Sim3Manifold;
  static constexpr int kDim = Camera::kObservationDim;
  static constexpr bool kHasPoint = true;
  using Observation = Eigen::Matrix<double, kDim, 1>;
  // @}

  // The keypoint observed in keyframe 1.
  Observation measurement;
  // The camera model (not owned).
  const Camera* camera = nullptr;

  // Residual and Jacobians (either may be null).
  void evaluate(const Sim3d& S12, const Eigen::Vector3d& point, Observation& r, Eigen::Matrix<double, kDim, 7>* jPose,
                Eigen::Matrix<double, kDim, 3>* jPoint) const {
    const Eigen::Vector3d q = S12 * point;
    r = camera->project(q) - measurement;
    if (!jPose && !jPoint) return;
    const Eigen::Matrix<double, kDim, 3> dProject = camera->projectJacobian(q);
    // exp(δ)·q moves q by υ + ω×q + σ·q to first order.
    if (jPose) jPose->noalias() = dProject * Sim3d::pointJacobianLeft(q);
    if (jPoint) jPoint->noalias() = S12.scale() * (dProject * S12.rotationMatrix());
  }
};

// The other direction: a point of keyframe 1 seen by keyframe 2 through S12⁻¹.
template <CameraModel Camera>
struct InverseSim3Reprojection {
  // @{
  // A Sim(3) pose with a point; rows: the camera's observation size.
  using PoseManifold = Sim3Manifold;
  static constexpr int kDim = Camera::kObservationDim;
  static constexpr bool kHasPoint = true;
  using Observation = Eigen::Matrix<double, kDim, 1>;
  // @}

  // The keypoint observed in keyframe 2.
  Observation measurement;
  // The camera model (not owned).
  const Camera* camera = nullptr;

  // Residual and Jacobians (either may be null).
  void evaluate(const Sim3d& S12, const Eigen::Vector3d& point, Observation& r, Eigen::Matrix<double, kDim, 7>* jPose,
                Eigen::Matrix<double, kDim, 3>* jPoint) const {
    const Sim3d S21 = S12.inverse();
    const Eigen::Vector3d q = S21 * point;
    r = camera->project(q) - measurement;
    if (!jPose && !jPoint) return;
    // (exp(δ)·S12)⁻¹·p = S21·exp(−δ)·p, and S21 acts on a displacement by s⁻¹·Rᵀ: the derivative
    // is −(s⁻¹·Rᵀ)·[I, −[p]×, p].
    const Eigen::Matrix<double, kDim, 3> dProjectA = camera->projectJacobian(q) * (S21.scale() * S21.rotationMatrix());
    if (jPose) jPose->noalias() = -dProjectA * Sim3d::pointJacobianLeft(point);
    if (jPoint) *jPoint = dProjectA;
  }
};

// @{
// The pinhole instances loop closing uses.
using MonoSim3Reprojection = Sim3Reprojection<PinholeCamera<double>>;
using MonoInverseSim3Reprojection = InverseSim3Reprojection<PinholeCamera<double>>;
// @}

}  // namespace orbis::optim
