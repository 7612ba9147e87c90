// orbis/camera/stereo.hpp — rectified stereo and RGB-D camera policies (3-D observations).
//
// Contract: both models observe a point as (uL, v, uR) with uR = uL - bf / Z, where bf is the
// left focal length times the baseline in metres (paper, section III-A). RectifiedStereoCamera
// is a real rectified pair; RgbdCamera turns a depth reading d (metres) into the same
// observation through a virtual baseline, so the rest of the system treats both alike.
// Points nearer than closeDepthThreshold() are "close" (trusted from one frame); it defaults
// to 40 baselines and the settings key ThDepth (in baselines) overrides it. Neither model
// checks z > 0: call inFront() first when the point may lie behind the camera.
#pragma once

#include <Eigen/Core>

#include "orbis/camera/pinhole.hpp"

namespace orbis {

namespace detail {

// The geometry both 3-D models share; not a camera model on its own (see the two below).
template <class S>
struct StereoGeometry {
  using Scalar = S;
  using Vector2 = Eigen::Matrix<S, 2, 1>;
  using Vector3 = Eigen::Matrix<S, 3, 1>;
  using Observation = Eigen::Matrix<S, 3, 1>;  // (uL, v, uR)
  using ProjectionJacobian = Eigen::Matrix<S, 3, 3>;

  static constexpr int kObservationDim = 3;
  static constexpr bool kMetricDepth = true;
  static constexpr S kDefaultCloseDepthInBaselines = S(40);

  PinholeCamera<S> pinhole;
  S baseline{};    // metres (virtual for RGB-D)
  S closeDepth{};  // metres

  StereoGeometry() = default;
  StereoGeometry(const PinholeCamera<S>& p, S baselineMetres, S closeDepthMetres)
      : pinhole(p), baseline(baselineMetres), closeDepth(closeDepthMetres) {}

  S bf() const { return pinhole.fx * baseline; }

  static bool inFront(const Vector3& pc) { return PinholeCamera<S>::inFront(pc); }

  Observation project(const Vector3& pc) const {
    const S invZ = S(1) / pc.z();
    const S uL = pinhole.fx * pc.x() * invZ + pinhole.cx;
    return {uL, pinhole.fy * pc.y() * invZ + pinhole.cy, uL - bf() * invZ};
  }

  // d project / d pc: the pinhole rows, and uR's row = uL's row + d(-bf/Z)/dZ.
  ProjectionJacobian projectJacobian(const Vector3& pc) const {
    ProjectionJacobian J;
    J.template topRows<2>() = pinhole.projectJacobian(pc);
    J.row(2) = J.row(0);
    J(2, 2) += bf() / (pc.z() * pc.z());
    return J;
  }

  S depthFromDisparity(S disparity) const { return bf() / disparity; }

  // Inverse of project(); needs a positive disparity uL - uR.
  Vector3 unproject(const Observation& obs) const {
    return pinhole.unproject(obs.template head<2>(), depthFromDisparity(obs.x() - obs.z()));
  }

  Vector3 unproject(const Vector2& px, S depth) const { return pinhole.unproject(px, depth); }

  bool inImage(S u, S v) const { return pinhole.inImage(u, v); }

  S closeDepthThreshold() const { return closeDepth; }
};

}  // namespace detail

// A rectified stereo pair: observation (uL, v, uR) with uR = uL − bf/Z; points nearer than
// closeDepth (ThDepth baselines) are close.
template <class S = double>
struct RectifiedStereoCamera : detail::StereoGeometry<S> {
  // The shared stereo geometry (projection, Jacobian, unprojection).
  using Base = detail::StereoGeometry<S>;

  // A rectified pair measures depth through a disparity of a few pixels for far points (beyond
  // closeDepthThreshold()), where a sub-pixel offset of the rectification or of the disparity
  // interpolation becomes a depth (scale) bias the same in every frame, which BA cannot average
  // away: far keypoints enter BA as monocular observations (bundleAdjustmentDepthLimit). A depth
  // sensor has no such offset and keeps its readings at every depth.
  static constexpr bool kFarDepthMonocular = true;

  RectifiedStereoCamera() = default;
  // A pair with the given baseline (metres) and ORB-SLAM2's close depth of 40 baselines.
  RectifiedStereoCamera(const PinholeCamera<S>& pinhole, S baseline)
      : Base(pinhole, baseline, Base::kDefaultCloseDepthInBaselines * baseline) {}
  // A pair with the given baseline and close depth (metres).
  RectifiedStereoCamera(const PinholeCamera<S>& pinhole, S baseline, S closeDepth)
      : Base(pinhole, baseline, closeDepth) {}

  // The same camera in another scalar type.
  template <class T>
  RectifiedStereoCamera<T> cast() const {
    return {this->pinhole.template cast<T>(), T(this->baseline), T(this->closeDepth)};
  }
};

// A colour camera with a depth sensor, observed like a stereo pair through a virtual baseline: a
// depth reading d becomes uR = uL − bf/d.
template <class S = double>
struct RgbdCamera : detail::StereoGeometry<S> {
  // The shared stereo geometry (projection, Jacobian, unprojection).
  using Base = detail::StereoGeometry<S>;

  // σ of the virtual disparity bf/d in pixels, beside a level-0 keypoint's 1 px (settings
  // DepthDisparitySigma). BA weighs a depth reading by it (optim/reprojection.hpp:
  // DisparityReprojection) instead of as a second keypoint's coordinate.
  static constexpr S kDefaultDisparitySigma = S(0.125);

  S depthScale = S(1);  // settings DepthMapFactor: raw depth value / depthScale = metres
  // σ of the virtual disparity, px (settings DepthDisparitySigma).
  S disparitySigma = kDefaultDisparitySigma;

  RgbdCamera() = default;
  // A depth camera with ORB-SLAM2's close depth of 40 virtual baselines; depthScaleFactor: raw
  // depth per metre.
  RgbdCamera(const PinholeCamera<S>& pinhole, S virtualBaseline, S depthScaleFactor)
      : Base(pinhole, virtualBaseline, Base::kDefaultCloseDepthInBaselines * virtualBaseline),
        depthScale(depthScaleFactor) {}
  // A depth camera with the given close depth (metres).
  RgbdCamera(const PinholeCamera<S>& pinhole, S virtualBaseline, S depthScaleFactor, S closeDepth)
      : Base(pinhole, virtualBaseline, closeDepth), depthScale(depthScaleFactor) {}

  // Metres of a raw depth-image value.
  S metricDepth(S rawDepth) const { return rawDepth / depthScale; }

  // The stereo observation a depth reading d (metres) at (uL, v) stands for.
  typename Base::Observation observationFromDepth(S uL, S v, S depth) const {
    return {uL, v, uL - this->bf() / depth};
  }

  // The same camera in another scalar type.
  template <class T>
  RgbdCamera<T> cast() const {
    RgbdCamera<T> c{this->pinhole.template cast<T>(), T(this->baseline), T(depthScale), T(this->closeDepth)};
    c.disparitySigma = T(disparitySigma);
    return c;
  }
};

}  // namespace orbis
