// orbis/optim/lie_manifolds.hpp — pose parameter blocks on SE(3) (and Sim(3) once available).
//
// Contract: the left update x ⊞ δ = exp(δ)·x with Sophus' tangent order (υ, ω[, σ]). Poses are
// stored as camera-from-world transforms T_cw, so δ perturbs the camera frame — the convention
// of ORB-SLAM's g2o vertices and of every residual in this directory. squaredNorm counts the unit
// quaternion (1) plus the translation, as Ceres would for a quaternion + translation block.
#pragma once

#include "orbis/geometry/se3.hpp"
#include "orbis/optim/manifold.hpp"

namespace orbis::optim {

struct SE3Manifold {
  static constexpr int kDim = 6;
  using Value = SE3d;
  using Tangent = SE3d::Tangent;
  static Value plus(const Value& x, const Tangent& delta) { return SE3d::exp(delta) * x; }
  static double squaredNorm(const Value& x) { return 1.0 + x.translation().squaredNorm(); }
};

}  // namespace orbis::optim
