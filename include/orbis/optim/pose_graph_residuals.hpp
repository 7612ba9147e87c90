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

struct RelativePoseSim3 {
  using PoseManifold = Sim3Manifold;
  static constexpr int kDim = 7;
  static constexpr bool kHasPoint = false;

  Sim3d measurement;  // S_ij

  void evaluate(const Sim3d& poseI, const Sim3d& poseJ, Eigen::Matrix<double, 7, 1>& r,
                Eigen::Matrix<double, 7, 7>* jI, Eigen::Matrix<double, 7, 7>* jJ) const {
    const Sim3d inverseMeasurement = measurement.inverse();
    r = (inverseMeasurement * poseI * poseJ.inverse()).log();
    if (jI) *jI = Sim3d::leftJacobianInverse(r) * inverseMeasurement.Adj();
    if (jJ) *jJ = -Sim3d::rightJacobianInverse(r);
  }
};

}  // namespace orbis::optim
