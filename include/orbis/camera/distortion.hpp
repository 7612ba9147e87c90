// orbis/camera/distortion.hpp — radial-tangential (OpenCV "plumb bob") lens distortion.
//
// Contract: RadTanDistortion maps an ideal point on the normalised image plane to where the
// lens puts it (distort) and back (undistort, by Newton iterations on the 2x2 system, which
// stay accurate where OpenCV's default five fixed-point iterations do not for strong barrel
// distortion such as EuRoC's k1 = -0.28). Coefficients follow OpenCV's order k1, k2, p1, p2, k3.
// undistortPoints() returns a copy of a keypoint list with the pixel positions undistorted; it
// accepts any keypoint with float members u, v, or a cv::Point2f member pt (cv::KeyPoint).
// Nothing here allocates except the returned vector, and nothing throws.
#pragma once

#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "orbis/camera/pinhole.hpp"

namespace orbis {

// Radial-tangential (Brown–Conrady, OpenCV's k1 k2 p1 p2 k3) lens distortion on normalised image
// coordinates.
template <class S = double>
struct RadTanDistortion {
  // @{
  // Vector and Jacobian types of the normalised image plane.
  using Vector2 = Eigen::Matrix<S, 2, 1>;
  using Matrix2 = Eigen::Matrix<S, 2, 2>;
  // @}

  // @{
  // The coefficients (settings Camera.k1, k2, p1, p2, k3).
  S k1{}, k2{}, p1{}, p2{}, k3{};
  // @}

  // Whether the lens has no distortion (the images are already undistorted).
  bool isZero() const { return k1 == S(0) && k2 == S(0) && p1 == S(0) && p2 == S(0) && k3 == S(0); }

  // The distorted normalised point of an undistorted one.
  Vector2 distort(const Vector2& xn) const {
    const S x = xn.x(), y = xn.y();
    const S r2 = x * x + y * y;
    const S radial = S(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x * radial + S(2) * p1 * x * y + p2 * (r2 + S(2) * x * x),
            y * radial + p1 * (r2 + S(2) * y * y) + S(2) * p2 * x * y};
  }

  // d distort / d xn.
  Matrix2 distortJacobian(const Vector2& xn) const {
    const S x = xn.x(), y = xn.y();
    const S r2 = x * x + y * y;
    const S radial = S(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
    const S dRadialDr2 = k1 + r2 * (S(2) * k2 + S(3) * k3 * r2);
    const S cross = S(2) * x * y * dRadialDr2 + S(2) * p1 * x + S(2) * p2 * y;
    Matrix2 J;
    J << radial + S(2) * x * x * dRadialDr2 + S(2) * p1 * y + S(6) * p2 * x, cross,  //
        cross, radial + S(2) * y * y * dRadialDr2 + S(6) * p1 * y + S(2) * p2 * x;
    return J;
  }

  // The ideal normalised point that distort() maps to xd; xd itself when the lens is ideal.
  Vector2 undistort(const Vector2& xd, int maxIterations = 20) const {
    if (isZero()) return xd;
    // Tolerance far below a pixel (1e-10 in normalised units is ~1e-7 px at f = 1000).
    const S tolerance2 = std::is_same_v<S, float> ? S(1e-12) : S(1e-20);
    Vector2 x = xd;
    for (int i = 0; i < maxIterations; ++i) {
      const Vector2 step = distortJacobian(x).inverse() * (distort(x) - xd);
      x -= step;
      if (step.squaredNorm() < tolerance2) break;
    }
    return x;
  }

  // The same distortion in another scalar type.
  template <class T>
  RadTanDistortion<T> cast() const {
    return {T(k1), T(k2), T(p1), T(p2), T(k3)};
  }
};

// The undistorted pixel of a pixel of the distorted image.
template <class S>
Eigen::Matrix<S, 2, 1> undistortPixel(const PinholeCamera<S>& camera, const RadTanDistortion<S>& lens,
                                      const Eigen::Matrix<S, 2, 1>& px) {
  return camera.normalizedToPixel(lens.undistort(camera.pixelToNormalized(px)));
}

// The distorted pixel of an undistorted one.
template <class S>
Eigen::Matrix<S, 2, 1> distortPixel(const PinholeCamera<S>& camera, const RadTanDistortion<S>& lens,
                                    const Eigen::Matrix<S, 2, 1>& px) {
  return camera.normalizedToPixel(lens.distort(camera.pixelToNormalized(px)));
}

template <class K>
concept KeypointWithUV = requires(K k) {
  { k.u } -> std::convertible_to<float>;
  { k.v } -> std::convertible_to<float>;
};

template <class K>
concept KeypointWithPt = requires(K k) {
  { k.pt.x } -> std::convertible_to<float>;
  { k.pt.y } -> std::convertible_to<float>;
};

// Copy of `keypoints` with positions undistorted (ORB-SLAM2 keeps both lists per frame).
template <class Keypoint>
  requires KeypointWithUV<Keypoint> || KeypointWithPt<Keypoint>
std::vector<Keypoint> undistortPoints(const std::vector<Keypoint>& keypoints,
                                      const PinholeCamera<double>& camera,
                                      const RadTanDistortion<double>& lens) {
  std::vector<Keypoint> out(keypoints);
  if (lens.isZero()) return out;
  for (Keypoint& k : out) {
    if constexpr (KeypointWithUV<Keypoint>) {
      const Eigen::Vector2d px = undistortPixel(camera, lens, Eigen::Vector2d(k.u, k.v));
      k.u = static_cast<float>(px.x());
      k.v = static_cast<float>(px.y());
    } else {
      const Eigen::Vector2d px = undistortPixel(camera, lens, Eigen::Vector2d(k.pt.x, k.pt.y));
      k.pt.x = static_cast<float>(px.x());
      k.pt.y = static_cast<float>(px.y());
    }
  }
  return out;
}

}  // namespace orbis
