// orbis/geometry/se3.hpp — rigid-body motions SE(3), templated on the scalar type.
//
// Contract: SE3<S> is a rotation SO3<S> (unit quaternion) plus a translation; it acts on points
// as R·p + t. The tangent is ξ = (υ, ω): translational part first, rotation vector second,
// exactly as Sophus, and exp(ξ) = (exp(ω), J_l(ω)·υ). Accuracy and angle range of exp/log are
// those of SO3 (exact near 0 and π). Jacobians follow SO3's left/right convention; the 6x6
// left Jacobian is [[J_l(ω), Q(υ,ω)], [0, J_l(ω)]] (Barfoot & Furgale's Q).
// The poses stored elsewhere in orbis are camera-to-world unless a name says otherwise.
#pragma once

#include "orbis/geometry/so3.hpp"

#include <cmath>

namespace orbis {

// A rigid motion: rotation and translation, acting on points as R·p + t (Sophus' conventions;
// tangent ordered (υ, ω)).
template <class S>
class SE3 {
 public:
  // @{
  // The scalar, the sizes and the Eigen types of the group, its tangent space and its matrices.
  using Scalar = S;
  static constexpr int kDoF = 6;
  static constexpr int kMatrixDim = 4;
  using Tangent = Eigen::Matrix<S, 6, 1>;
  using Point = Eigen::Matrix<S, 3, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Matrix3 = Eigen::Matrix<S, 3, 3>;
  using Matrix4 = Eigen::Matrix<S, 4, 4>;
  using Matrix3x4 = Eigen::Matrix<S, 3, 4>;
  using Matrix6 = Eigen::Matrix<S, 6, 6>;
  using Transformation = Matrix4;
  using AdjointMatrix = Matrix6;
  using Quaternion = Eigen::Quaternion<S>;
  // @}

  SE3() : translation_(Vector3::Zero()) {}
  // @{
  // A motion from its rotation (SO3, unit quaternion or rotation matrix) and translation.
  SE3(const SO3<S>& rotation, const Vector3& translation)
      : so3_(rotation), translation_(translation) {}
  SE3(const Quaternion& rotation, const Vector3& translation)
      : so3_(rotation), translation_(translation) {}
  SE3(const Matrix3& rotation, const Vector3& translation)
      : so3_(rotation), translation_(translation) {}
  // @}

  // Reads the top 3x4 block; the bottom row is ignored. The rotation block is re-normalised.
  template <class Derived>
  static SE3 fromMatrix(const Eigen::MatrixBase<Derived>& m) {
    static_assert((Derived::RowsAtCompileTime == 4 || Derived::RowsAtCompileTime == 3) &&
                      Derived::ColsAtCompileTime == 4,
                  "SE3::fromMatrix expects a 4x4 or 3x4 matrix");
    return SE3(Matrix3(m.template block<3, 3>(0, 0).template cast<S>()),
               Vector3(m.template block<3, 1>(0, 3).template cast<S>()));
  }

  // The motion of a tangent vector (υ, ω).
  static SE3 exp(const Tangent& xi) {
    const Vector3 omega = xi.template tail<3>();
    return SE3(SO3<S>::exp(omega), SO3<S>::leftJacobian(omega) * xi.template head<3>());
  }

  // The tangent vector of this motion; exp(log()) is the identity for rotations below π.
  Tangent log() const {
    const Vector3 omega = so3_.log();
    Tangent xi;
    xi.template head<3>() = SO3<S>::leftJacobianInverse(omega) * translation_;
    xi.template tail<3>() = omega;
    return xi;
  }

  // [[hat(ω), υ], [0, 0]]
  static Matrix4 hat(const Tangent& xi) {
    Matrix4 m = Matrix4::Zero();
    m.template block<3, 3>(0, 0) = SO3<S>::hat(xi.template tail<3>());
    m.template block<3, 1>(0, 3) = xi.template head<3>();
    return m;
  }
  // The tangent vector of a 4×4 Lie-algebra matrix.
  static Tangent vee(const Matrix4& m) {
    Tangent xi;
    xi.template head<3>() = m.template block<3, 1>(0, 3);
    xi.template tail<3>() = SO3<S>::vee(m.template block<3, 3>(0, 0));
    return xi;
  }

  // The inverse motion.
  SE3 inverse() const {
    const SO3<S> inv = so3_.inverse();
    return SE3(inv, -(inv * translation_));
  }

  // @{
  // Composition: (this · other)(p) = this(other(p)).
  SE3 operator*(const SE3& other) const {
    return SE3(so3_ * other.so3_, so3_ * other.translation_ + translation_);
  }
  SE3& operator*=(const SE3& other) { return *this = *this * other; }
  // @}
  // The motion applied to a point: R·p + t.
  Point operator*(const Point& p) const { return so3_ * p + translation_; }

  // The 4×4 homogeneous matrix.
  Matrix4 matrix() const {
    Matrix4 m = Matrix4::Identity();
    m.template block<3, 4>(0, 0) = matrix3x4();
    return m;
  }
  // The top 3×4 block [R | t].
  Matrix3x4 matrix3x4() const {
    Matrix3x4 m;
    m.template block<3, 3>(0, 0) = so3_.matrix();
    m.template block<3, 1>(0, 3) = translation_;
    return m;
  }

  // [[R, hat(t)·R], [0, R]]
  Matrix6 Adj() const {
    const Matrix3 R = so3_.matrix();
    Matrix6 a;
    a.template block<3, 3>(0, 0) = R;
    a.template block<3, 3>(0, 3) = SO3<S>::hat(translation_) * R;
    a.template block<3, 3>(3, 0).setZero();
    a.template block<3, 3>(3, 3) = R;
    return a;
  }

  // @{
  // The rotation and the translation, read and set.
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

  // The left Jacobian of exp: exp(ξ + δ) ≈ exp(J_l(ξ)·δ)·exp(ξ).
  static Matrix6 leftJacobian(const Tangent& xi) {
    const Vector3 omega = xi.template tail<3>();
    const Matrix3 J = SO3<S>::leftJacobian(omega);
    Matrix6 out;
    out.template block<3, 3>(0, 0) = J;
    out.template block<3, 3>(0, 3) = translationalCoupling(xi.template head<3>(), omega);
    out.template block<3, 3>(3, 0).setZero();
    out.template block<3, 3>(3, 3) = J;
    return out;
  }
  // Block inverse of the upper-triangular left Jacobian: [[J⁻¹, −J⁻¹QJ⁻¹], [0, J⁻¹]].
  static Matrix6 leftJacobianInverse(const Tangent& xi) {
    const Vector3 omega = xi.template tail<3>();
    const Matrix3 Jinv = SO3<S>::leftJacobianInverse(omega);
    Matrix6 out;
    out.template block<3, 3>(0, 0) = Jinv;
    out.template block<3, 3>(0, 3) =
        -Jinv * translationalCoupling(xi.template head<3>(), omega) * Jinv;
    out.template block<3, 3>(3, 0).setZero();
    out.template block<3, 3>(3, 3) = Jinv;
    return out;
  }
  // @{
  // The right Jacobian of exp and its inverse: exp(ξ + δ) ≈ exp(ξ)·exp(J_r(ξ)·δ).
  static Matrix6 rightJacobian(const Tangent& xi) { return leftJacobian(-xi); }
  static Matrix6 rightJacobianInverse(const Tangent& xi) { return leftJacobianInverse(-xi); }
  // @}

  // d(exp(δ)·q)/dδ at δ = 0 for the transformed point q = T·p: [I, −hat(q)].
  static Eigen::Matrix<S, 3, 6> pointJacobianLeft(const Point& transformedPoint) {
    Eigen::Matrix<S, 3, 6> j;
    j.template block<3, 3>(0, 0).setIdentity();
    j.template block<3, 3>(0, 3) = -SO3<S>::hat(transformedPoint);
    return j;
  }

  // The same motion in another scalar type.
  template <class T>
  SE3<T> cast() const {
    return SE3<T>(so3_.template cast<T>(), translation_.template cast<T>());
  }

 private:
  // Q(υ, ω), the upper-right block of the left Jacobian (Barfoot & Furgale 2014, eq. 102):
  // ½Υ + c1(ΩΥ + ΥΩ + ΩΥΩ) + c2(Ω²Υ + ΥΩ² − 3ΩΥΩ) + c3(ΩΥΩ² + Ω²ΥΩ).
  static Matrix3 translationalCoupling(const Vector3& upsilon, const Vector3& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const S theta2 = omega.squaredNorm();
    S c1, c2, c3;
    if (theta2 < lie_detail::Numerics<S>::smallAngle() * lie_detail::Numerics<S>::smallAngle()) {
      const S theta4 = theta2 * theta2;
      c1 = S(1) / S(6) - theta2 / S(120) + theta4 / S(5040);
      c2 = S(1) / S(24) - theta2 / S(720) + theta4 / S(40320);
      c3 = S(1) / S(120) - theta2 / S(2520) + theta4 / S(120960);
    } else {
      const S theta = sqrt(theta2);
      const S s = sin(theta);
      const S c = cos(theta);
      c1 = (theta - s) / (theta2 * theta);
      c2 = (theta2 + S(2) * c - S(2)) / (S(2) * theta2 * theta2);
      c3 = (S(2) * theta - S(3) * s + theta * c) / (S(2) * theta2 * theta2 * theta);
    }
    const Matrix3 W = SO3<S>::hat(omega);
    const Matrix3 U = SO3<S>::hat(upsilon);
    const Matrix3 WU = W * U;
    const Matrix3 UW = U * W;
    const Matrix3 WUW = WU * W;
    const Matrix3 WW = W * W;
    return S(0.5) * U + c1 * (WU + UW + WUW) + c2 * (WW * U + UW * W - S(3) * WUW) +
           c3 * (WUW * W + W * WUW);
  }

  SO3<S> so3_;
  Vector3 translation_;
};

// @{
// SE3 in double and float.
using SE3d = SE3<double>;
using SE3f = SE3<float>;
// @}

}  // namespace orbis
