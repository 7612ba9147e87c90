// orbis/optim/pose_graph_residuals.hpp — relative-pose residuals between two camera poses, the
// edges of ORB-SLAM's essential graph.
//
// Contract: poses are camera-from-world (T_iw, T_jw); the measurement is the relative transform
// T_ij = T_iw·T_jw⁻¹ observed when the edge was made. r = log(T_ij⁻¹·T_iw·T_jw⁻¹) ∈ se(3) (Sophus
// order υ, ω), zero when the edge is satisfied. Jacobians for the left update of each pose:
// ∂r/∂δ_i = J_l⁻¹(r)·Ad(T_ij⁻¹), ∂r/∂δ_j = −J_r⁻¹(r).
#pragma once

#include "orbis/optim/lie_manifolds.hpp"

#include <Eigen/Core>

namespace orbis::optim {

struct RelativePoseSE3 {
  using PoseManifold = SE3Manifold;
  static constexpr int kDim = 6;
  static constexpr bool kHasPoint = false;

  SE3d measurement;  // T_ij

  void evaluate(const SE3d& poseI, const SE3d& poseJ, Eigen::Matrix<double, 6, 1>& r,
                Eigen::Matrix<double, 6, 6>* jI, Eigen::Matrix<double, 6, 6>* jJ) const {
    const SE3d inverseMeasurement = measurement.inverse();
    r = (inverseMeasurement * poseI * poseJ.inverse()).log();
    if (jI) *jI = SE3d::leftJacobianInverse(r) * inverseMeasurement.Adj();
    if (jJ) *jJ = -SE3d::rightJacobianInverse(r);
  }
};

}  // namespace orbis::optim
