// orbis/geometry/so3.hpp — the rotation group SO(3), templated on the scalar type.
//
// Contract: SO3<S> stores one unit quaternion (4 scalars). The tangent is the rotation vector
// φ (axis·angle). exp and log are accurate to rounding for every angle in [0, π]: Taylor series
// near zero, and log reads the angle as 2·atan2(|q_vec|, |q_w|), which stays well conditioned
// near π where acos-based formulas fail. log returns angles in [0, π].
// Jacobians: exp(φ + δ) ≈ exp(leftJacobian(φ)·δ)·exp(φ) ≈ exp(φ)·exp(rightJacobian(φ)·δ),
// and log(exp(δ)·exp(φ)) ≈ φ + leftJacobianInverse(φ)·δ (right likewise).
// Constructors from a quaternion or rotation matrix re-normalise. Products renormalise only
// when rounding has pushed |q|² measurably away from 1; normalize() does it on demand.
#pragma once

#include "orbis/geometry/lie_group.hpp"

#include <cmath>

namespace orbis {

// A 3-D rotation, held as a unit quaternion (Sophus' conventions).
template <class S>
class SO3 {
 public:
  // @{
  // The scalar, the sizes and the Eigen types of the group, its tangent space and its matrices.
  using Scalar = S;
  static constexpr int kDoF = 3;
  static constexpr int kMatrixDim = 3;
  using Tangent = Eigen::Matrix<S, 3, 1>;
  using Point = Eigen::Matrix<S, 3, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Matrix3 = Eigen::Matrix<S, 3, 3>;
  using Transformation = Matrix3;
  using AdjointMatrix = Matrix3;
  using Quaternion = Eigen::Quaternion<S>;
  // @}

  SO3() : q_(Quaternion::Identity()) {}
  // The rotation of a quaternion (normalised here).
  explicit SO3(const Quaternion& q) : q_(q) { normalize(); }
  // Any 3x3 close to a rotation; the result is the rotation of its (normalised) quaternion.
  explicit SO3(const Matrix3& rotation) : q_(rotation) { normalize(); }

  // The rotation of a rotation matrix.
  static SO3 fromMatrix(const Matrix3& rotation) { return SO3(rotation); }

  // The rotation of a rotation vector ω (angle |ω| about ω).
  static SO3 exp(const Tangent& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const S theta2 = omega.squaredNorm();
    S real, imagFactor;  // q = (cos(θ/2), sin(θ/2)/θ · φ)
    if (theta2 < lie_detail::Numerics<S>::smallAngle() * lie_detail::Numerics<S>::smallAngle()) {
      const S theta4 = theta2 * theta2;
      real = S(1) - theta2 / S(8) + theta4 / S(384);
      imagFactor = S(0.5) - theta2 / S(48) + theta4 / S(3840);
    } else {
      const S theta = sqrt(theta2);
      real = cos(theta / S(2));
      imagFactor = sin(theta / S(2)) / theta;
    }
    SO3 r;
    r.q_.w() = real;
    r.q_.vec() = imagFactor * omega;
    return r;
  }

  // The rotation vector of this rotation.
  Tangent log() const {
    using std::abs;
    using std::atan2;
    using std::sqrt;
    // q and −q are the same rotation; using |w| keeps the angle in [0, π].
    const S w = q_.w();
    const S absW = abs(w);
    const S n2 = q_.vec().squaredNorm();
    S angleOverN;  // θ / |q_vec|, with θ = 2·atan2(|q_vec|, |w|)
    const S small = lie_detail::Numerics<S>::smallAngle();
    if (n2 < small * small * w * w) {
      // 2·atan(x)/n with x = n/|w|: series in x² avoids 0/0 at the identity.
      const S x2 = n2 / (w * w);
      angleOverN = S(2) / absW * (S(1) - x2 / S(3) + x2 * x2 / S(5));
    } else {
      const S n = sqrt(n2);
      angleOverN = S(2) * atan2(n, absW) / n;
    }
    if (w < S(0)) angleOverN = -angleOverN;
    return angleOverN * q_.vec();
  }

  // @{
  // Between rotation vectors and skew-symmetric matrices.
  static Matrix3 hat(const Tangent& omega) { return lie_detail::skew<S>(omega); }
  static Tangent vee(const Matrix3& m) { return Tangent(m(2, 1), m(0, 2), m(1, 0)); }
  // @}

  // The inverse rotation.
  SO3 inverse() const { return fromUnitQuaternion(q_.conjugate()); }

  // @{
  // Composition: (this · other)(p) = this(other(p)).
  SO3 operator*(const SO3& other) const {
    using std::abs;
    using std::sqrt;
    Quaternion q = q_ * other.q_;
    const S n2 = q.squaredNorm();
    if (abs(n2 - S(1)) > lie_detail::Numerics<S>::quaternionDrift()) q.coeffs() /= sqrt(n2);
    return fromUnitQuaternion(q);
  }
  SO3& operator*=(const SO3& other) { return *this = *this * other; }
  // @}

  // The rotation applied to a point.
  Point operator*(const Point& p) const { return q_ * p; }

  // @{
  // The rotation matrix and the unit quaternion.
  Matrix3 matrix() const { return q_.toRotationMatrix(); }
  const Quaternion& unitQuaternion() const { return q_; }
  // @}
  // The four quaternion coefficients (x, y, z, w), e.g. for an optimiser's parameter block.
  const S* data() const { return q_.coeffs().data(); }

  // Rotations act on their own tangent vectors by rotation: R·exp(φ)·R⁻¹ = exp(R·φ).
  Matrix3 Adj() const { return matrix(); }

  // Renormalises the quaternion after many compositions.
  void normalize() { q_.normalize(); }

  // exp(φ + δ) ≈ exp(J_l(φ)·δ)·exp(φ).  J_l = I + (1−cosθ)/θ²·Φ + (θ−sinθ)/θ³·Φ².
  static Matrix3 leftJacobian(const Tangent& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const S theta2 = omega.squaredNorm();
    const Matrix3 Phi = hat(omega);
    S a, b;
    if (theta2 < lie_detail::Numerics<S>::smallAngle() * lie_detail::Numerics<S>::smallAngle()) {
      const S theta4 = theta2 * theta2;
      a = S(0.5) - theta2 / S(24) + theta4 / S(720);
      b = S(1) / S(6) - theta2 / S(120) + theta4 / S(5040);
    } else {
      const S theta = sqrt(theta2);
      const S halfSin = sin(theta / S(2));
      a = S(2) * halfSin * halfSin / theta2;  // (1−cosθ)/θ² without its cancellation
      b = (theta - sin(theta)) / (theta2 * theta);
    }
    return Matrix3::Identity() + a * Phi + b * (Phi * Phi);
  }

  // J_l⁻¹ = I − ½Φ + (1 − (θ/2)·cot(θ/2))/θ²·Φ²; finite up to and including θ = π.
  static Matrix3 leftJacobianInverse(const Tangent& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const S theta2 = omega.squaredNorm();
    const Matrix3 Phi = hat(omega);
    S c;
    if (theta2 < lie_detail::Numerics<S>::smallAngle() * lie_detail::Numerics<S>::smallAngle()) {
      c = S(1) / S(12) + theta2 / S(720) + theta2 * theta2 / S(30240);
    } else {
      const S half = sqrt(theta2) / S(2);
      c = (S(1) - half * cos(half) / sin(half)) / theta2;
    }
    return Matrix3::Identity() - S(0.5) * Phi + c * (Phi * Phi);
  }

  // @{
  // The right Jacobian of exp and its inverse: exp(φ + δ) ≈ exp(φ)·exp(J_r(φ)·δ).
  static Matrix3 rightJacobian(const Tangent& omega) { return leftJacobian(-omega); }
  static Matrix3 rightJacobianInverse(const Tangent& omega) { return leftJacobianInverse(-omega); }
  // @}

  // d(exp(δ)·q)/dδ at δ = 0, where q = R·p is the rotated point.
  static Eigen::Matrix<S, 3, 3> pointJacobianLeft(const Point& rotatedPoint) {
    return -hat(rotatedPoint);
  }

  // The same rotation in another scalar type.
  template <class T>
  SO3<T> cast() const {
    return SO3<T>(q_.template cast<T>());
  }

  // The quaternion must already be unit (within rounding); no normalisation is done.
  static SO3 fromUnitQuaternion(const Quaternion& q) {
    SO3 r;
    r.q_ = q;
    return r;
  }

 private:
  Quaternion q_;
};

// @{
// SO3 in double and float.
using SO3d = SO3<double>;
using SO3f = SO3<float>;
// @}

}  // namespace orbis
