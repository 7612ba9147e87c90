// orbis/camera/pinhole.hpp — the monocular pinhole camera policy.
//
// Contract: an ideal (undistorted, or already undistorted) pinhole camera with focal lengths
// fx, fy and principal point cx, cy in pixels. project() maps a point in the camera frame
// (z forward, x right, y down) to a pixel; it does not check z > 0: call inFront() first when
// the point may lie behind the camera. Observations are 2-D, depth is not metric.
// width/height == 0 means "not known yet" (ORB-SLAM2 settings files may omit them).
#pragma once

#include <limits>

#include <Eigen/Core>

namespace orbis {

// A pinhole camera: a 2-D observation (u, v) of a point in the camera frame; no lens distortion
// (RadTanDistortion undistorts keypoints first).
template <class S = double>
struct PinholeCamera {
  // @{
  // The scalar, vector, observation and Jacobian types.
  using Scalar = S;
  using Vector2 = Eigen::Matrix<S, 2, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Observation = Vector2;
  using ProjectionJacobian = Eigen::Matrix<S, 2, 3>;
  // @}

  // @{
  // A 2-D observation, without metric depth.
  static constexpr int kObservationDim = 2;
  static constexpr bool kMetricDepth = false;
  // @}

  // @{
  // Focal lengths and principal point, pixels.
  S fx{}, fy{}, cx{}, cy{};
  // @}
  // @{
  // Image size in pixels (0: not known yet).
  int width = 0, height = 0;
  // @}

  // Points closer than this are not projected: the projection and its Jacobian blow up at z = 0.
  static constexpr S kMinDepth = S(1e-6);

  // Whether a point lies in front of the camera (z > kMinDepth).
  static bool inFront(const Vector3& pc) { return pc.z() > kMinDepth; }

  // The pixel a camera-frame point projects to.
  Observation project(const Vector3& pc) const {
    const S invZ = S(1) / pc.z();
    return {fx * pc.x() * invZ + cx, fy * pc.y() * invZ + cy};
  }

  // The point at the given depth (z, not range) seen at pixel px. Multiplying before dividing
  // keeps normalizedRay (depth 1) exact and gives the map's depth points their historical bits.
  Vector3 unproject(const Vector2& px, S depth) const {
    return {(px.x() - cx) * depth / fx, (px.y() - cy) * depth / fy, depth};
  }

  // Point on the normalised image plane (z = 1) seen at pixel px.
  Vector3 normalizedRay(const Vector2& px) const { return unproject(px, S(1)); }

  // Pixel <-> normalised image plane coordinates (x/z, y/z), where lens distortion acts.
  Vector2 pixelToNormalized(const Vector2& px) const { return {(px.x() - cx) / fx, (px.y() - cy) / fy}; }
  // Pixel coordinates of a point on the normalised image plane.
  Vector2 normalizedToPixel(const Vector2& xn) const { return {fx * xn.x() + cx, fy * xn.y() + cy}; }

  // d project / d pc.
  ProjectionJacobian projectJacobian(const Vector3& pc) const {
    const S invZ = S(1) / pc.z();
    const S invZ2 = invZ * invZ;
    ProjectionJacobian J;
    J << fx * invZ, S(0), -fx * pc.x() * invZ2,  //
        S(0), fy * invZ, -fy * pc.y() * invZ2;
    return J;
  }

  // Whether (u, v) lies inside the image.
  bool inImage(S u, S v) const {
    return u >= S(0) && v >= S(0) && u < S(width) && v < S(height);
  }

  // A monocular camera measures no depth, so every point counts as "far".
  S closeDepthThreshold() const { return std::numeric_limits<S>::infinity(); }

  // The 3×3 camera matrix.
  Eigen::Matrix<S, 3, 3> K() const {
    Eigen::Matrix<S, 3, 3> k;
    k << fx, S(0), cx, S(0), fy, cy, S(0), S(0), S(1);
    return k;
  }

  // The same camera in another scalar type.
  template <class T>
  PinholeCamera<T> cast() const {
    return {T(fx), T(fy), T(cx), T(cy), width, height};
  }
};

}  // namespace orbis
