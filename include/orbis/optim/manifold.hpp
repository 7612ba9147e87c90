// orbis/optim/manifold.hpp — parameter-block policies: what a variable is and how it moves.
//
// Contract: a Manifold policy names the stored Value, its tangent dimension kDim, and
// plus(x, δ) — the local update the solver applies after each accepted step. Jacobians of
// residuals are taken with respect to δ at δ = 0, so a residual and the manifold it is written
// against must agree on the update (SE(3) and Sim(3) use the left update exp(δ)·T; see
// lie_manifolds.hpp). Euclidean blocks (3-D points, BAL's 9-parameter camera) add δ.
// squaredNorm(x) is the size of the stored parameters, used only by the step-size stopping rule.
#pragma once

#include <Eigen/Core>

#include <concepts>
#include <vector>

namespace orbis::optim {

template <class M>
concept Manifold = requires(const typename M::Value& x,
                            const Eigen::Matrix<double, M::kDim, 1>& delta) {
  typename M::Value;
  { M::kDim } -> std::convertible_to<int>;
  { M::plus(x, delta) } -> std::convertible_to<typename M::Value>;
  { M::squaredNorm(x) } -> std::convertible_to<double>;
};

// An N-dimensional Euclidean block (x + δ).
template <int N>
struct EuclideanManifold {
  // @{
  // Its dimension, value and tangent.
  static constexpr int kDim = N;
  using Value = Eigen::Matrix<double, N, 1>;
  using Tangent = Eigen::Matrix<double, N, 1>;
  // @}
  // x + δ.
  static Value plus(const Value& x, const Tangent& delta) { return x + delta; }
  // ‖x‖².
  static double squaredNorm(const Value& x) { return x.squaredNorm(); }
};

// 3-D points.
using PointManifold = EuclideanManifold<3>;

// std::vector with Eigen's aligned allocator: the fixed-size blocks stored here are
// vectorisable types, and this keeps them correctly aligned whatever the language mode.
template <class T>
using AlignedVector = std::vector<T, Eigen::aligned_allocator<T>>;

}  // namespace orbis::optim
