// orbis/optim/lie_manifolds.hpp — pose parameter blocks on SE(3) and Sim(3).
//
// Contract: the left update x ⊞ δ = exp(δ)·x with Sophus' tangent order (υ, ω[, σ]). Poses are
// stored as camera-from-world transforms T_cw, so δ perturbs the camera frame — the convention
// of ORB-SLAM's g2o vertices and of every residual in this directory. squaredNorm counts the unit
// quaternion (1) plus the translation (and the scale), as Ceres would for such a block.
#pragma once

#include "orbis/geometry/se3.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/optim/manifold.hpp"

namespace orbis::optim {

// SE(3) poses with the left update exp(δ)·T.
struct SE3Manifold {
  // @{
  // Six degrees of freedom: the value and its tangent.
  static constexpr int kDim = 6;
  using Value = SE3d;
  using Tangent = SE3d::Tangent;
  // @}
  // exp(δ)·x.
  static Value plus(const Value& x, const Tangent& delta) { return SE3d::exp(delta) * x; }
  // Scale of x for the relative step test.
  static double squaredNorm(const Value& x) { return 1.0 + x.translation().squaredNorm(); }
};

// Sim(3) poses with the left update exp(δ)·S.
struct Sim3Manifold {
  // @{
  // Seven degrees of freedom: the value and its tangent.
  static constexpr int kDim = 7;
  using Value = Sim3d;
  using Tangent = Sim3d::Tangent;
  // @}
  // exp(δ)·x.
  static Value plus(const Value& x, const Tangent& delta) { return Sim3d::exp(delta) * x; }
  // Scale of x for the relative step test.
  static double squaredNorm(const Value& x) {
    return 1.0 + x.translation().squaredNorm() + x.scale() * x.scale();
  }
};

}  // namespace orbis::optim
