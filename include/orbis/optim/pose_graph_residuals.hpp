// orbis/optim/pose_graph_residuals.hpp — relative-pose residuals between two camera poses, the
// edges of ORB-SLAM's essential graph.
//
// Contract: poses are camera-from-world (T_iw, T_jw); the measurement is the relative transform
// T_ij = T_iw·T_jw⁻¹ observed when the edge was made. r = log(T_ij⁻¹·T_iw·T_jw⁻¹) ∈ se(3) (Sophus
// order υ, ω), zero when the edge is satisfied. Jacobians for the left update of each pose:
// ∂r/∂δ_i = J_l⁻¹(r)·Ad(T_ij⁻¹), ∂r/∂δ_j = −J_r⁻¹(r). RelativePoseSim3 is the same on Sim(3)
// (r ∈ sim(3), order υ, ω, σ), for monocular maps whose loops also correct scale drift.
#pragma once

#include "orbis/optim/lie_manifolds.hpp"

#include <Eigen/Core>

namespace orbis::optim {

// One residual for both groups: Manifold is SE3Manifold or Sim3Manifold.
template <class Manifold>
struct RelativePose {
  // @{
  // The manifold, its group, the residual's size (the tangent's) and no point.
  using PoseManifold = Manifold;
  using Group = typename Manifold::Value;
  static constexpr int kDim = Manifold::kDim;
  static constexpr bool kHasPoint = false;
  // @}

  Group measurement;  // T_ij (or S_ij)

  // r = log(T_ij⁻¹ · T_i · T_j⁻¹), with its Jacobians (either may be null).
  void evaluate(const Group& poseI, const Group& poseJ, Eigen::Matrix<double, kDim, 1>& r,
                Eigen::Matrix<double, kDim, kDim>* jI, Eigen::Matrix<double, kDim, kDim>* jJ) const {
    const Group inverseMeasurement = measurement.inverse();
    r = (inverseMeasurement * poseI * poseJ.inverse()).log();
    if (jI) *jI = Group::leftJacobianInverse(r) * inverseMeasurement.Adj();
    if (jJ) *jJ = -Group::rightJacobianInverse(r);
  }
};

// @{
// The residual for SE(3) and Sim(3) pose graphs.
using RelativePoseSE3 = RelativePose<SE3Manifold>;
using RelativePoseSim3 = RelativePose<Sim3Manifold>;
// @}

}  // namespace orbis::optim
