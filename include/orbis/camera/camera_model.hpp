// orbis/camera/camera_model.hpp — the CameraModel concept and its traits.
//
// Contract: a camera model is a small value type, templated on its scalar, that maps a point
// in the camera frame to an observation of kObservationDim (2: pixel; 3: (uL, v, uR)) rows
// and back, with the analytic Jacobian of the projection. Code generic over cameras takes
// `template <CameraModel Camera>` and asks CameraTraits<Camera> (or the members) for the
// observation size, whether depth is metric, and the close/far depth threshold.
// A new camera is one struct that satisfies the concept; nothing else changes.
//
// A type that is not a camera fails with the concept's name in the diagnostic, for instance
//   static_assert(orbis::CameraModel<int>);        // error: ... 'int' does not satisfy CameraModel
// tests/camera/camera_model_test.cpp holds such negative checks.
#pragma once

#include <limits>

#include <concepts>

#include <Eigen/Core>

#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/stereo.hpp"

namespace orbis {

template <class C>
concept CameraModel =
    std::floating_point<typename C::Scalar> &&
    (C::kObservationDim == 2 || C::kObservationDim == 3) &&
    std::convertible_to<decltype(C::kMetricDepth), bool> &&
    requires(const C& camera, const Eigen::Matrix<typename C::Scalar, 3, 1>& pc,
             const Eigen::Matrix<typename C::Scalar, 2, 1>& px, typename C::Scalar value) {
      { camera.project(pc) } -> std::same_as<Eigen::Matrix<typename C::Scalar, C::kObservationDim, 1>>;
      { camera.projectJacobian(pc) } -> std::same_as<Eigen::Matrix<typename C::Scalar, C::kObservationDim, 3>>;
      { camera.unproject(px, value) } -> std::same_as<Eigen::Matrix<typename C::Scalar, 3, 1>>;
      { C::inFront(pc) } -> std::same_as<bool>;
      { camera.inImage(value, value) } -> std::same_as<bool>;
      { camera.closeDepthThreshold() } -> std::same_as<typename C::Scalar>;
    };

// What only cameras that measure depth have (rectified stereo, RGB-D): an observation
// (uL, v, uR) with uR = uL - bf/Z, the left image's pinhole, and the stereo baseline.
template <class C>
concept StereoCameraModel = CameraModel<C> && C::kObservationDim == 3 && C::kMetricDepth &&
    requires(const C& camera, const Eigen::Matrix<typename C::Scalar, 3, 1>& obs) {
      { camera.bf() } -> std::same_as<typename C::Scalar>;
      { camera.baseline } -> std::convertible_to<typename C::Scalar>;
      { camera.pinhole } -> std::convertible_to<PinholeCamera<typename C::Scalar>>;
      { camera.unproject(obs) } -> std::same_as<Eigen::Matrix<typename C::Scalar, 3, 1>>;
    };

// The pinhole of the left (or only) image: where 2-D observations, normalised rays, epipolar
// geometry and PnP live, whatever the camera adds on top of it.
template <CameraModel C>
const PinholeCamera<typename C::Scalar>& pinholeOf(const C& camera) {
  if constexpr (requires { camera.pinhole; }) {
    return camera.pinhole;
  } else {
    return camera;
  }
}

// What the pipeline asks of any camera model, in one place.
template <CameraModel C>
struct CameraTraits {
  // @{
  // The camera's scalar, its observation type and size, and whether it measures metric depth.
  using Scalar = typename C::Scalar;
  using Observation = Eigen::Matrix<Scalar, C::kObservationDim, 1>;
  static constexpr int kObservationDim = C::kObservationDim;
  static constexpr bool kMetricDepth = C::kMetricDepth;
  // @}
  // Depth below which a point counts as close (stereo-measured).
  static Scalar closeDepthThreshold(const C& camera) { return camera.closeDepthThreshold(); }
};

// Keypoints measured deeper than this enter bundle adjustment (motion-only, local and full) as
// monocular observations, their depth left to the views' parallax: the close-depth threshold of a
// camera model that declares kFarDepthMonocular (RectifiedStereoCamera), else infinity (ORB-SLAM2:
// every stereo reading is a stereo residual).
template <CameraModel C>
double bundleAdjustmentDepthLimit(const C& camera) {
  if constexpr (requires { C::kFarDepthMonocular; }) {
    if constexpr (C::kFarDepthMonocular) return static_cast<double>(camera.closeDepthThreshold());
  }
  return std::numeric_limits<double>::infinity();
}

static_assert(CameraModel<PinholeCamera<double>> && CameraModel<PinholeCamera<float>>);
static_assert(CameraModel<RectifiedStereoCamera<double>> && CameraModel<RectifiedStereoCamera<float>>);
static_assert(CameraModel<RgbdCamera<double>> && CameraModel<RgbdCamera<float>>);
static_assert(StereoCameraModel<RectifiedStereoCamera<double>> && StereoCameraModel<RgbdCamera<double>>);
static_assert(!StereoCameraModel<PinholeCamera<double>>);

}  // namespace orbis
