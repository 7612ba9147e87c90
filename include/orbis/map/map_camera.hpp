// orbis/map/map_camera.hpp — the camera model a map's intrinsics stand for.
//
// Contract: visitCamera(K, f) calls f once with the compile-time camera model K describes —
// PinholeCamera when bf = 0, RgbdCamera when a depth sensor's disparitySigma > 0, else
// RectifiedStereoCamera — built from K's fx, fy, cx, cy, bf (baseline bf / fx) and returns what f
// returns. The map stores plain intrinsics; code that runs templated per sensor (bundle
// adjustment) picks its model here, once per call, not per observation.
#pragma once

#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/map/key_frame.hpp"

namespace orbis {

template <class F>
decltype(auto) visitCamera(const MapIntrinsics& K, F&& f) {
  const PinholeCamera<double> pinhole{K.fx, K.fy, K.cx, K.cy, 0, 0};
  if (K.bf <= 0) return f(pinhole);
  const double baseline = K.bf / K.fx;
  if (K.disparitySigma > 0) {
    RgbdCamera<double> rgbd(pinhole, baseline, 1.0, K.closeDepth);
    rgbd.disparitySigma = K.disparitySigma;
    return f(rgbd);
  }
  return f(RectifiedStereoCamera<double>(pinhole, baseline, K.closeDepth));
}

}  // namespace orbis
