// orbis/tracking/frame.hpp — the frame being tracked: features, pose and map-point matches.
//
// Contract: a Frame is built once from a sensor's images (system/frame_builder.hpp) and then
// only its pose, its matches and their outlier flags change. Features are shared, immutable,
// with the keyframe it may become. Sensor-agnostic: uRight < 0 marks a monocular keypoint.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "orbis/bow/bow_vector.hpp"
#include "orbis/map/key_frame.hpp"

namespace orbis {

struct Frame {
  std::uint64_t index = 0;
  double timestamp = 0;
  std::shared_ptr<const FrameFeatures> features;
  MapIntrinsics intrinsics;
  bool isRgbd = false;  // depth from a sensor rather than stereo matching (wider search windows)

  bow::BowVector bow;
  bow::FeatureVector featureVector;
  bool hasBow = false;

  SE3d Tcw;
  std::vector<MapPoint*> points;  // one slot per keypoint; null when unmatched
  std::vector<char> outlier;      // set by motion-only BA

  std::size_t size() const { return points.size(); }
  Eigen::Vector3d cameraCenter() const { return Tcw.inverse().translation(); }
  void resetMatches() {
    points.assign(features ? features->size() : 0, nullptr);
    outlier.assign(points.size(), 0);
  }
  // Number of matched, non-outlier points.
  int inliers() const {
    int n = 0;
    for (std::size_t i = 0; i < points.size(); ++i) n += (points[i] && !outlier[i]) ? 1 : 0;
    return n;
  }
  bool isStereo(std::size_t i) const { return features->uRight[i] >= 0; }
  bool isClose(std::size_t i) const {
    const float d = features->depth[i];
    return d > 0 && d < intrinsics.closeDepth;
  }
  // World point of keypoint i from its depth (stereo or RGB-D), using the current pose.
  bool unprojectStereo(std::size_t i, Eigen::Vector3d& world) const {
    const float z = features->depth[i];
    if (!(z > 0)) return false;
    const Keypoint& k = features->keypointsUn[i];
    const Eigen::Vector3d pc((k.u - intrinsics.cx) * z / intrinsics.fx, (k.v - intrinsics.cy) * z / intrinsics.fy, z);
    world = Tcw.inverse() * pc;
    return true;
  }
};

}  // namespace orbis
