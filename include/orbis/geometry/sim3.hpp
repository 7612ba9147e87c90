// orbis/geometry/sim3.hpp — similarity transforms Sim(3), templated on the scalar type.
//
// Contract: Sim3<S> is a scale s > 0, a rotation SO3<S> and a translation; it acts on points as
// s·R·p + t (a monocular map's drift is such a transform). The tangent is ξ = (υ, ω, σ) with
// s = exp(σ), exactly as Sophus; exp(ξ) = (exp(σ), exp(ω), W(σ, ω)·υ). Rotation angles behave as
// in SO3 (exact near 0 and π); W is closed-form away from (σ, θ) = 0 and a series near it.
// Jacobians follow SO3's left/right convention; they have no compact closed form here and are
// computed as φ1(ad ξ) by scaling-and-squaring (accurate to rounding, ~7x7 matrix products
// each), so use them in optimisers' linearisation, not in per-point loops.
// Constructors do not check s > 0; a non-positive scale is the caller's bug.
#pragma once

#include "orbis/geometry/se3.hpp"
#include "orbis/geometry/so3.hpp"

#include <cmath>

namespace orbis {

// A similarity: scale, rotation and translation, acting on points as s·R·p + t (Sophus'
// conventions; tangent ordered (υ, ω, σ), scale exp(σ)).
template <class S>
class Sim3 {
 public:
  // @{
  // The scalar, the sizes and the Eigen types of the group, its tangent space and its matrices.
  using Scalar = S;
  static constexpr int kDoF = 7;
  static constexpr int kMatrixDim = 4;
  using Tangent = Eigen::Matrix<S, 7, 1>;
  using Point = Eigen::Matrix<S, 3, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Matrix3 = Eigen::Matrix<S, 3, 3>;
  using Matrix4 = Eigen::Matrix<S, 4, 4>;
  using Matrix3x4 = Eigen::Matrix<S, 3, 4>;
  using Matrix7 = Eigen::Matrix<S, 7, 7>;
  using Transformation = Matrix4;
  using AdjointMatrix = Matrix7;
  using Quaternion = Eigen::Quaternion<S>;
  // @}

  Sim3() : scale_(1), translation_(Vector3::Zero()) {}
  // @{
  // A similarity from its scale, rotation (SO3, unit quaternion or rotation matrix) and
  // translation.
  Sim3(S scale, const SO3<S>& rotation, const Vector3& translation)
      : scale_(scale), so3_(rotation), translation_(translation) {}
  Sim3(S scale, const Quaternion& rotation, const Vector3& translation)
      : scale_(scale), so3_(rotation), translation_(translation) {}
  Sim3(S scale, const Matrix3& rotation, const Vector3& translation)
      : scale_(scale), so3_(rotation), translation_(translation) {}
  // @}
  // A rigid motion as a similarity of scale 1.
  explicit Sim3(const SE3<S>& pose)
      : scale_(1), so3_(pose.so3()), translation_(pose.translation()) {}

  // Reads the top 3x4 block [s·R | t]; s is the cube root of det(s·R), R is re-normalised.
  template <class Derived>
  static Sim3 fromMatrix(const Eigen::MatrixBase<Derived>& m) {
    static_assert((Derived::RowsAtCompileTime == 4 || Derived::RowsAtCompileTime == 3) &&
                      Derived::ColsAtCompileTime == 4,
                  "Sim3::fromMatrix expects a 4x4 or 3x4 matrix");
    using std::cbrt;
    const Matrix3 sR = m.template block<3, 3>(0, 0).template cast<S>();
    const S s = cbrt(sR.determinant());
    return Sim3(s, Matrix3(sR / s), Vector3(m.template block<3, 1>(0, 3).template cast<S>()));
  }

  // The similarity of a tangent vector (υ, ω, σ).
  static Sim3 exp(const Tangent& xi) {
    using std::exp;
    const S sigma = xi[6];
    const Vector3 omega = xi.template segment<3>(3);
    return Sim3(exp(sigma), SO3<S>::exp(omega),
                scaledRotationIntegral(sigma, omega) * xi.template head<3>());
  }

  // The tangent vector of this similarity.
  Tangent log() const {
    using std::log;
    Tangent xi;
    const S sigma = log(scale_);
    const Vector3 omega = so3_.log();
    // W is invertible for θ < 2π (its eigenvalues are φ1(σ), φ1(σ ± iθ)).
    xi.template head<3>() = scaledRotationIntegral(sigma, omega).inverse() * translation_;
    xi.template segment<3>(3) = omega;
    xi[6] = sigma;
    return xi;
  }

  // [[σI + hat(ω), υ], [0, 0]]
  static Matrix4 hat(const Tangent& xi) {
    Matrix4 m = Matrix4::Zero();
    m.template block<3, 3>(0, 0) =
        SO3<S>::hat(xi.template segment<3>(3)) + xi[6] * Matrix3::Identity();
    m.template block<3, 1>(0, 3) = xi.template head<3>();
    return m;
  }
  // The tangent vector of a 4×4 Lie-algebra matrix.
  static Tangent vee(const Matrix4& m) {
    Tangent xi;
    xi.template head<3>() = m.template block<3, 1>(0, 3);
    xi.template segment<3>(3) = SO3<S>::vee(m.template block<3, 3>(0, 0));
    xi[6] = m(0, 0);
    return xi;
  }

  // The Lie bracket as a matrix: ad(ξ)·η = vee([hat ξ, hat η]).
  static Matrix7 ad(const Tangent& xi) {
    const Vector3 upsilon = xi.template head<3>();
    const Matrix3 Omega = SO3<S>::hat(xi.template segment<3>(3));
    Matrix7 a = Matrix7::Zero();
    a.template block<3, 3>(0, 0) = Omega + xi[6] * Matrix3::Identity();
    a.template block<3, 3>(0, 3) = SO3<S>::hat(upsilon);
    a.template block<3, 1>(0, 6) = -upsilon;
    a.template block<3, 3>(3, 3) = Omega;
    return a;
  }

  // The inverse similarity.
  Sim3 inverse() const {
    const SO3<S> inv = so3_.inverse();
    const S invScale = S(1) / scale_;
    return Sim3(invScale, inv, -invScale * (inv * translation_));
  }

  // @{
  // Composition: (this · other)(p) = this(other(p)).
  Sim3 operator*(const Sim3& other) const {
    return Sim3(scale_ * other.scale_, so3_ * other.so3_,
                scale_ * (so3_ * other.translation_) + translation_);
  }
  Sim3& operator*=(const Sim3& other) { return *this = *this * other; }
  // @}
  // The similarity applied to a point: s·R·p + t.
  Point operator*(const Point& p) const { return scale_ * (so3_ * p) + translation_; }

  // The 4×4 matrix [sR t; 0 1].
  Matrix4 matrix() const {
    Matrix4 m = Matrix4::Identity();
    m.template block<3, 4>(0, 0) = matrix3x4();
    return m;
  }
  // The top 3×4 block [sR | t].
  Matrix3x4 matrix3x4() const {
    Matrix3x4 m;
    m.template block<3, 3>(0, 0) = scale_ * so3_.matrix();
    m.template block<3, 1>(0, 3) = translation_;
    return m;
  }

  // [[sR, hat(t)·R, −t], [0, R, 0], [0, 0, 1]]
  Matrix7 Adj() const {
    const Matrix3 R = so3_.matrix();
    Matrix7 a = Matrix7::Zero();
    a.template block<3, 3>(0, 0) = scale_ * R;
    a.template block<3, 3>(0, 3) = SO3<S>::hat(translation_) * R;
    a.template block<3, 1>(0, 6) = -translation_;
    a.template block<3, 3>(3, 3) = R;
    a(6, 6) = S(1);
    return a;
  }

  // @{
  // The scale, rotation and translation, read and set.
  S scale() const { return scale_; }
  void setScale(S scale) { scale_ = scale; }
  const SO3<S>& so3() const { return so3_; }
  SO3<S>& so3() { return so3_; }
  Matrix3 rotationMatrix() const { return so3_.matrix(); }
  const Quaternion& unitQuaternion() const { return so3_.unitQuaternion(); }
  const Vector3& translation() const { return translation_; }
  Vector3& translation() { return translation_; }
  void setRotation(const SO3<S>& rotation) { so3_ = rotation; }
  void setTranslation(const Vector3& translation) { translation_ = translation; }
  // @}
  // Renormalises the rotation's quaternion after many compositions.
  void normalize() { so3_.normalize(); }

  // @{
  // The left Jacobian of exp and its inverse: exp(ξ + δ) ≈ exp(J_l(ξ)·δ)·exp(ξ).
  static Matrix7 leftJacobian(const Tangent& xi) { return lie_detail::phi1<S, 7>(ad(xi)); }
  static Matrix7 leftJacobianInverse(const Tangent& xi) {
    return leftJacobian(xi).partialPivLu().inverse();
  }
  // @}
  // @{
  // The right Jacobian of exp and its inverse: exp(ξ + δ) ≈ exp(ξ)·exp(J_r(ξ)·δ).
  static Matrix7 rightJacobian(const Tangent& xi) { return leftJacobian(-xi); }
  static Matrix7 rightJacobianInverse(const Tangent& xi) { return leftJacobianInverse(-xi); }
  // @}

  // d(exp(δ)·q)/dδ at δ = 0 for the transformed point q = S·p: [I, −hat(q), q].
  static Eigen::Matrix<S, 3, 7> pointJacobianLeft(const Point& transformedPoint) {
    Eigen::Matrix<S, 3, 7> j;
    j.template block<3, 3>(0, 0).setIdentity();
    j.template block<3, 3>(0, 3) = -SO3<S>::hat(transformedPoint);
    j.template block<3, 1>(0, 6) = transformedPoint;
    return j;
  }

  // The same similarity in another scalar type.
  template <class T>
  Sim3<T> cast() const {
    return Sim3<T>(T(scale_), so3_.template cast<T>(), translation_.template cast<T>());
  }

 private:
  // W(σ, ω) = ∫₀¹ e^{στ}·exp(τ·hat ω) dτ = a·I + b·Ω + c·Ω², the map from υ to the translation.
  // With z = σ + iθ and φ1(z) = (e^z − 1)/z: a = φ1(σ), b = Im φ1(z)/θ, c = (a − Re φ1(z))/θ².
  static Matrix3 scaledRotationIntegral(S sigma, const Vector3& omega) {
    using std::abs;
    using std::cos;
    using std::exp;
    using std::expm1;
    using std::sin;
    using std::sqrt;
    const Matrix3 Omega = SO3<S>::hat(omega);
    const S theta2 = omega.squaredNorm();
    const S theta = sqrt(theta2);
    // Near σ = θ = 0 every closed form below is 0/0; the series of φ1(σI + Ω) is exact there.
    if (abs(sigma) + theta < S(0.5)) {
      return lie_detail::phi1<S, 3>(Matrix3(Omega + sigma * Matrix3::Identity()));
    }
    const S es = exp(sigma);
    const S a = abs(sigma) < lie_detail::Numerics<S>::tinyAngle()
                    ? S(1) + sigma / S(2) + sigma * sigma / S(6)
                    : expm1(sigma) / sigma;
    S b, c;
    if (theta < lie_detail::Numerics<S>::tinyAngle()) {
      // θ → 0 limits; here |σ| ≥ ½, so their own divisions by σ are harmless.
      const S sigma2 = sigma * sigma;
      b = (es * (sigma - S(1)) + S(1)) / sigma2;
      c = (es * (sigma2 - S(2) * sigma + S(2)) - S(2)) / (S(2) * sigma2 * sigma);
    } else {
      const S denom = sigma * sigma + theta2;
      const S cosT = cos(theta);
      const S sinT = sin(theta);
      b = (es * sigma * sinT / theta - (es * cosT - S(1))) / denom;
      const S re = ((es * cosT - S(1)) * sigma + es * sinT * theta) / denom;
      // Cancels for small θ, but then Ω² is O(θ²): the absolute error of c·Ω² stays O(ε).
      c = (a - re) / theta2;
    }
    return a * Matrix3::Identity() + b * Omega + c * (Omega * Omega);
  }

  S scale_;
  SO3<S> so3_;
  Vector3 translation_;
};

// @{
// Sim3 in double and float.
using Sim3d = Sim3<double>;
using Sim3f = Sim3<float>;
// @}

}  // namespace orbis
