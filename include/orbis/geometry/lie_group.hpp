// orbis/geometry/lie_group.hpp — what every Lie group of orbis provides, and shared numerics.
//
// Contract: a LieGroup G (SO3, SE3, Sim3, each templated on its Scalar) is a value type whose
// default constructor is the identity. G::exp maps a tangent vector (G::Tangent, G::kDoF
// entries, ordered as in Sophus) to the group and g.log() maps back; log∘exp is the identity
// for rotation angles in [0, π). Composition is operator*, acting on 3-D points is operator*
// with G::Point. g.Adj() satisfies g·exp(ξ)·g⁻¹ = exp(Adj·ξ); hat/vee convert between tangent
// vectors and the Lie algebra's matrices (G::kMatrixDim square). pointJacobianLeft(q) is the
// derivative of exp(δ)·q with respect to δ at δ = 0, q being the already-transformed point.
// Nothing here allocates or throws; all types are fixed-size Eigen and safe in std::vector.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <concepts>

namespace orbis {

template <class G>
concept LieGroup = requires(const G g, const typename G::Tangent xi, const typename G::Point p,
                            const typename G::Transformation m) {
  typename G::Scalar;
  requires std::same_as<typename G::Tangent, Eigen::Matrix<typename G::Scalar, G::kDoF, 1>>;
  requires std::same_as<typename G::Point, Eigen::Matrix<typename G::Scalar, 3, 1>>;
  { G() };
  { G::exp(xi) } -> std::same_as<G>;
  { g.log() } -> std::same_as<typename G::Tangent>;
  { g.inverse() } -> std::same_as<G>;
  { g * g } -> std::same_as<G>;
  { g * p } -> std::same_as<typename G::Point>;
  { g.matrix() } -> std::same_as<typename G::Transformation>;
  requires std::same_as<typename G::AdjointMatrix,
                        Eigen::Matrix<typename G::Scalar, G::kDoF, G::kDoF>>;
  { g.Adj() } -> std::same_as<typename G::AdjointMatrix>;
  { G::hat(xi) } -> std::same_as<typename G::Transformation>;
  { G::vee(m) } -> std::same_as<typename G::Tangent>;
  { G::pointJacobianLeft(p) } -> std::same_as<Eigen::Matrix<typename G::Scalar, 3, G::kDoF>>;
  { g.template cast<double>() };
};

// Groups that also give the Jacobians of exp and their inverses (SO3, SE3, Sim3):
//   exp(ξ + δ) ≈ exp(leftJacobian(ξ)·δ)·exp(ξ) ≈ exp(ξ)·exp(rightJacobian(ξ)·δ),
//   log(exp(δ)·exp(ξ)) ≈ ξ + leftJacobianInverse(ξ)·δ, and likewise on the right.
template <class G>
concept LieGroupWithJacobians = LieGroup<G> && requires(const typename G::Tangent xi) {
  { G::leftJacobian(xi) } -> std::same_as<typename G::AdjointMatrix>;
  { G::leftJacobianInverse(xi) } -> std::same_as<typename G::AdjointMatrix>;
  { G::rightJacobian(xi) } -> std::same_as<typename G::AdjointMatrix>;
  { G::rightJacobianInverse(xi) } -> std::same_as<typename G::AdjointMatrix>;
};

namespace lie_detail {

// Where the numerics switch, per scalar type (float needs far larger thresholds than double).
//  smallAngle: below it the closed forms lose digits to cancellation (the worst,
//    (2θ−3sinθ+θcosθ)/θ⁵ in SE3's Q, loses ~ε/θ absolute), so Taylor series to θ⁴ take over;
//    their truncation error is below ε there.
//  tinyAngle: below it a closed form is 0/0 outright; the θ → 0 limit replaces it where the
//    neglected terms are O(θ²) relative and multiply quantities that are themselves O(θ²).
//  quaternionDrift: how far |q|² may stray from 1 before a product renormalises.
template <class S>
struct Numerics {
  static S smallAngle() { return S(1e-2); }
  static S tinyAngle() { return S(1e-7); }
  static S quaternionDrift() { return S(1e-12); }
};
template <>
struct Numerics<float> {
  static float smallAngle() { return 0.25f; }
  static float tinyAngle() { return 3e-4f; }
  static float quaternionDrift() { return 1e-6f; }
};

// φ1(M) = Σ_k M^k/(k+1)! = ∫₀¹ exp(τM) dτ for a fixed-size square M, the left Jacobian of a
// matrix Lie group when M = ad(ξ). Taylor series on M/2^s (norm ≤ ½, degree 12: truncation
// below double's ε), then s doublings φ1(2X) = ½(exp(X) + I)·φ1(X), exp(2X) = exp(X)².
template <class S, int N>
Eigen::Matrix<S, N, N> phi1(const Eigen::Matrix<S, N, N>& m) {
  using Matrix = Eigen::Matrix<S, N, N>;
  const S norm = m.cwiseAbs().rowwise().sum().maxCoeff();
  int doublings = 0;
  S shrink(1);
  while (norm * shrink > S(0.5) && doublings < 60) {
    shrink /= S(2);
    ++doublings;
  }
  const Matrix x = m * shrink;
  const Matrix identity = Matrix::Identity();
  constexpr int kDegree = 12;
  Matrix p = identity;
  for (int k = kDegree; k >= 1; --k) p = identity + (x * p) / S(k + 1);  // Horner
  Matrix e = identity + x * p;                                            // exp(X) = I + X·φ1(X)
  for (int i = 0; i < doublings; ++i) {
    p = (S(0.5) * (e + identity) * p).eval();
    e = (e * e).eval();
  }
  return p;
}

template <class S>
inline Eigen::Matrix<S, 3, 3> skew(const Eigen::Matrix<S, 3, 1>& v) {
  Eigen::Matrix<S, 3, 3> m;
  m << S(0), -v.z(), v.y(),  //
      v.z(), S(0), -v.x(),   //
      -v.y(), v.x(), S(0);
  return m;
}

}  // namespace lie_detail
}  // namespace orbis
