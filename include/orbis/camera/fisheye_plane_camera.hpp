// orbis/camera/fisheye_plane_camera.hpp — a fisheye lens whose keypoints the pipeline keeps on
// the lens's tangent plane, and whose measurements it weighs through the lens.
//
// Contract: FisheyePlaneCamera is the MonocularFisheye sensor's camera model. As a CameraModel it
// is the tangent-plane pinhole (the lens's fx, fy, cx, cy; `pinhole`, what pinholeOf returns):
// observations, matching grids, epipolar geometry, two-view initialisation and PnP work on exact
// rays put on that plane. What depends on the pixel noise goes through the lens (`lens`, a
// KannalaBrandtCamera) instead, where ORB's error is isotropic: lensPixel() turns a plane
// observation back into the fisheye pixel it came from (bundle adjustment's residuals and the
// χ² gates are in those pixels), and windowStretch() says how far one fisheye pixel of error
// reaches on the plane at a point (matching windows are widened by it). A camera model that has
// both is ObservesThroughLens; the pipeline asks that at compile time, so the pinhole sensors'
// code and results are untouched. docs/notes/2026-11-26-fisheye.md explains the choice.
// Nothing here allocates or throws.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>

#include <Eigen/Core>

#include "orbis/camera/camera_model.hpp"
#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/camera/pinhole.hpp"

namespace orbis {

// A Kannala–Brandt lens seen on its tangent plane: the plane's pinhole for geometry, the lens for
// the noise.
template <class S = double>
struct FisheyePlaneCamera {
  // @{
  // The scalar, vector, observation and Jacobian types (the plane's).
  using Scalar = S;
  using Vector2 = Eigen::Matrix<S, 2, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Observation = Vector2;
  using ProjectionJacobian = Eigen::Matrix<S, 2, 3>;
  using Lens = KannalaBrandtCamera<S>;
  // @}

  // @{
  // A 2-D observation, without metric depth.
  static constexpr int kObservationDim = 2;
  static constexpr bool kMetricDepth = false;
  // @}

  // The tangent plane: the pinhole with the lens's focal lengths and principal point.
  PinholeCamera<S> pinhole;
  // The lens the images were taken through.
  Lens lens;

  // The camera of a lens.
  static FisheyePlaneCamera ofLens(const Lens& lens) { return {lens.centralPinhole(), lens}; }

  // @{
  // The plane's pinhole model.
  static bool inFront(const Vector3& pc) { return PinholeCamera<S>::inFront(pc); }
  Observation project(const Vector3& pc) const { return pinhole.project(pc); }
  ProjectionJacobian projectJacobian(const Vector3& pc) const { return pinhole.projectJacobian(pc); }
  Vector3 unproject(const Vector2& px, S depth) const { return pinhole.unproject(px, depth); }
  bool inImage(S u, S v) const { return pinhole.inImage(u, v); }
  S closeDepthThreshold() const { return std::numeric_limits<S>::infinity(); }
  // @}

  // The fisheye pixel of a tangent-plane observation (both see the same ray).
  Vector2 lensPixel(const Vector2& planePx) const { return lens.project(pinhole.normalizedRay(planePx)); }

  // How many plane pixels one fisheye pixel spans at the camera-frame point pc, along the
  // direction it stretches most: radially, d tanθ / dθd = 1 / (cos²θ · θd'(θ)) (tangentially
  // tanθ / θd, never more). 1 on the axis; infinite at and beyond 90°.
  S windowStretch(const Vector3& pc) const {
    const S r = std::hypot(pc.x(), pc.y());
    const S theta = std::atan2(r, pc.z());
    const S c = std::cos(theta);
    const S derivative = lens.distortAngleDerivative(theta);
    if (!(c > S(0)) || !(derivative > S(0))) return std::numeric_limits<S>::infinity();
    return std::max(S(1), S(1) / (c * c * derivative));
  }

  // The same camera in another scalar type.
  template <class T>
  FisheyePlaneCamera<T> cast() const {
    return {pinhole.template cast<T>(), lens.template cast<T>()};
  }
};

// A camera model whose 2-D observations live on a plane but whose pixel noise lives in a lens's
// image: bundle adjustment takes its residuals in lens pixels, matching widens its windows.
template <class C>
concept ObservesThroughLens = CameraModel<C> && C::kObservationDim == 2 &&
    requires(const C& camera, const typename C::Vector2& px, const typename C::Vector3& pc) {
      { camera.lens } -> std::convertible_to<typename C::Lens>;
      { camera.lensPixel(px) } -> std::same_as<typename C::Vector2>;
      { camera.windowStretch(pc) } -> std::same_as<typename C::Scalar>;
    };

// The factor a matching window around the projection of camera-frame point pc is widened by:
// the lens's stretch there, 1 for a camera without one (exactly: multiplying by it changes no bit).
template <CameraModel C>
float searchWindowStretch(const C& camera, const Eigen::Vector3d& pc) {
  if constexpr (ObservesThroughLens<C>) {
    return static_cast<float>(std::min(camera.windowStretch(pc.template cast<typename C::Scalar>()), typename C::Scalar(1e3)));
  } else {
    (void)camera, (void)pc;
    return 1.f;
  }
}

static_assert(CameraModel<FisheyePlaneCamera<double>> && CameraModel<FisheyePlaneCamera<float>>);
static_assert(ObservesThroughLens<FisheyePlaneCamera<double>> && !ObservesThroughLens<PinholeCamera<double>>);
static_assert(!StereoCameraModel<FisheyePlaneCamera<double>>);

}  // namespace orbis
