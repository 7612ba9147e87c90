// orbis/camera/kannala_brandt.hpp — the Kannala–Brandt (equidistant fisheye) camera model.
//
// Contract: KannalaBrandtCamera maps a point in the camera frame (z forward, x right, y down)
// to a pixel through the angle θ between its ray and the optical axis:
//   θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸),  u = fx θd x/r + cx,  v = fy θd y/r + cy,
// r = sqrt(x² + y²): OpenCV's cv::fisheye model, ORB-SLAM3's "KannalaBrandt8", Kalibr's
// "equidistant". Unlike a pinhole it is defined for every direction but straight backwards, so
// points at and beyond 90° off axis (behind the image plane, z ≤ 0) project: inFront() asks only
// that the ray is not (nearly) the backward axis, where the pixel is undefined; whether the lens
// actually sees the direction is inFieldOfView() (θ up to maxAngle, which a settings file or
// calibration sets: the polynomial is only trusted over the angles it was fitted on) and where
// the pixel falls is inImage(). unproject(px, depth) returns the point on the pixel's ray with
// that z (depth along the optical axis, as PinholeCamera: negative behind the image plane);
// bearing(px) the unit ray, unprojectJacobian(px) its derivative. θ is found from θd by Newton
// iterations on the polynomial, which is monotonic over the lens's field of view.
// Nothing here allocates or throws.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Core>

#include "orbis/camera/camera_model.hpp"
#include "orbis/camera/pinhole.hpp"

namespace orbis {

template <class S = double>
struct KannalaBrandtCamera {
  using Scalar = S;
  using Vector2 = Eigen::Matrix<S, 2, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Observation = Vector2;
  using ProjectionJacobian = Eigen::Matrix<S, 2, 3>;
  using UnprojectionJacobian = Eigen::Matrix<S, 3, 2>;

  static constexpr int kObservationDim = 2;
  static constexpr bool kMetricDepth = false;

  S fx{}, fy{}, cx{}, cy{};
  S k1{}, k2{}, k3{}, k4{};
  int width = 0, height = 0;
  // Largest angle off axis (radians) the lens sees and the polynomial is trusted at; π: any.
  S maxAngle = S(std::numbers::pi);

  // Rays closer than this (radians) to the backward axis have no defined pixel.
  static constexpr S kBackwardMargin = S(1e-3);

  static bool inFront(const Vector3& pc) {
    const S r = std::hypot(pc.x(), pc.y());
    return pc.norm() > S(1e-9) && std::atan2(r, pc.z()) < S(std::numbers::pi) - kBackwardMargin;
  }

  bool inFieldOfView(const Vector3& pc) const {
    return inFront(pc) && std::atan2(std::hypot(pc.x(), pc.y()), pc.z()) <= maxAngle;
  }

  // θd(θ) and dθd/dθ.
  S distortAngle(S theta) const {
    const S t2 = theta * theta;
    return theta * (S(1) + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))));
  }
  S distortAngleDerivative(S theta) const {
    const S t2 = theta * theta;
    return S(1) + t2 * (S(3) * k1 + t2 * (S(5) * k2 + t2 * (S(7) * k3 + t2 * S(9) * k4)));
  }

  // The angle off axis whose distorted angle is thetaD (Newton from θ = θd; ORB-SLAM3 and
  // OpenCV do the same). Stops at maxAngle's neighbourhood rather than run off a non-monotonic
  // polynomial.
  S undistortAngle(S thetaD) const {
    if (k1 == S(0) && k2 == S(0) && k3 == S(0) && k4 == S(0)) return thetaD;
    const S tolerance = std::is_same_v<S, float> ? S(1e-7) : S(1e-14);
    S theta = thetaD;
    for (int i = 0; i < 20; ++i) {
      const S derivative = distortAngleDerivative(theta);
      if (!(std::abs(derivative) > S(1e-9))) break;
      const S step = (distortAngle(theta) - thetaD) / derivative;
      theta = std::clamp(theta - step, S(0), S(std::numbers::pi));
      if (std::abs(step) < tolerance) break;
    }
    return theta;
  }

  Observation project(const Vector3& pc) const {
    const S r = std::hypot(pc.x(), pc.y());
    // On (or within rounding of) the axis θd/r → 1/z, the pinhole's scale.
    const S scale = r < S(1e-12) * std::abs(pc.z()) ? S(1) / pc.z() : distortAngle(std::atan2(r, pc.z())) / r;
    return {fx * scale * pc.x() + cx, fy * scale * pc.y() + cy};
  }

  // d project / d pc (see docs/notes/2026-11-26-fisheye.md for the derivation).
  ProjectionJacobian projectJacobian(const Vector3& pc) const {
    const S x = pc.x(), y = pc.y(), z = pc.z();
    const S r2 = x * x + y * y, r = std::sqrt(r2);
    ProjectionJacobian J;
    if (r < S(1e-7) * std::abs(z)) {  // the pinhole limit on the axis (θd ≈ θ ≈ r/z)
      const S invZ = S(1) / z;
      J << fx * invZ, S(0), -fx * x * invZ * invZ, S(0), fy * invZ, -fy * y * invZ * invZ;
      return J;
    }
    const S rho2 = r2 + z * z;
    const S theta = std::atan2(r, z);
    const S thetaD = distortAngle(theta), dThetaD = distortAngleDerivative(theta);
    const S psi = thetaD / r;                                  // pixel scale per unit of x, y
    const S a = dThetaD * z / (r2 * rho2) - thetaD / (r2 * r);  // (dψ/dx) / x = (dψ/dy) / y
    const S dPsiDz = -dThetaD / rho2;
    J << fx * (psi + x * x * a), fx * x * y * a, fx * x * dPsiDz,  //
        fy * x * y * a, fy * (psi + y * y * a), fy * y * dPsiDz;
    return J;
  }

  // The unit ray seen at pixel px (any direction the model reaches, z ≤ 0 included).
  Vector3 bearing(const Vector2& px) const {
    const S mx = (px.x() - cx) / fx, my = (px.y() - cy) / fy;
    const S thetaD = std::hypot(mx, my);
    if (thetaD < S(1e-12)) return Vector3(mx, my, S(1)).normalized();
    const S theta = undistortAngle(thetaD);
    const S s = std::sin(theta) / thetaD;
    return {s * mx, s * my, std::cos(theta)};
  }

  // d bearing / d px.
  UnprojectionJacobian unprojectJacobian(const Vector2& px) const {
    const S mx = (px.x() - cx) / fx, my = (px.y() - cy) / fy;
    const S thetaD = std::hypot(mx, my);
    UnprojectionJacobian dm;  // d bearing / d (mx, my)
    if (thetaD < S(1e-7)) {
      dm << S(1), S(0), S(0), S(1), -mx, -my;  // bearing ≈ (mx, my, 1 - |m|²/2)
    } else {
      const S theta = undistortAngle(thetaD);
      const S dTheta = S(1) / distortAngleDerivative(theta);  // dθ/dθd
      const S sinT = std::sin(theta), cosT = std::cos(theta);
      const S s = sinT / thetaD;
      const S dsDThetaD = (cosT * dTheta - s) / thetaD;  // ds/dθd
      const S ux = mx / thetaD, uy = my / thetaD;       // dθd/dmx, dθd/dmy
      dm << s + mx * dsDThetaD * ux, mx * dsDThetaD * uy,  //
          my * dsDThetaD * ux, s + my * dsDThetaD * uy,    //
          -sinT * dTheta * ux, -sinT * dTheta * uy;
    }
    dm.col(0) /= fx;
    dm.col(1) /= fy;
    return dm;
  }

  // The point at depth z seen at pixel px: the ray scaled to that z (undefined at 90° off axis,
  // where the ray never reaches another z; a negative z is a point behind the image plane).
  Vector3 unproject(const Vector2& px, S depth) const {
    const Vector3 b = bearing(px);
    return b * (depth / b.z());
  }

  // The point at distance `range` from the centre along the pixel's ray.
  Vector3 unprojectRange(const Vector2& px, S range) const { return bearing(px) * range; }

  bool inImage(S u, S v) const { return u >= S(0) && v >= S(0) && u < S(width) && v < S(height); }

  S closeDepthThreshold() const { return std::numeric_limits<S>::infinity(); }

  // The field of view across the image's width/height/diagonal through the principal point,
  // degrees (what `orbis synth` and the guide quote).
  S horizontalFieldOfViewDegrees() const {
    return (undistortAngle(cx / fx) + undistortAngle((S(width) - cx) / fx)) * S(180) / S(std::numbers::pi);
  }

  template <class T>
  KannalaBrandtCamera<T> cast() const {
    KannalaBrandtCamera<T> c;
    c.fx = T(fx), c.fy = T(fy), c.cx = T(cx), c.cy = T(cy);
    c.k1 = T(k1), c.k2 = T(k2), c.k3 = T(k3), c.k4 = T(k4);
    c.width = width, c.height = height, c.maxAngle = T(maxAngle);
    return c;
  }

  // The focal lengths and principal point alone, as a pinhole (what tangent-plane geometry near
  // the axis uses).
  PinholeCamera<S> centralPinhole() const { return {fx, fy, cx, cy, width, height}; }
};

// ORB-SLAM3's name for the model.
template <class S = double>
using KannalaBrandt8 = KannalaBrandtCamera<S>;

static_assert(CameraModel<KannalaBrandtCamera<double>> && CameraModel<KannalaBrandtCamera<float>>);
static_assert(!StereoCameraModel<KannalaBrandtCamera<double>>);

}  // namespace orbis
