// orbis/map/map_matching.hpp — descriptor searches between frames, keyframes and map points.
//
// Contract: the searches of ORB-SLAM's tracking, mapping and relocalisation, written on the map
// types and templated on the sensor's camera model (every projection goes through it; the
// stereo coordinate uR is checked only for a StereoCameraModel): each projects or groups
// candidates, compares 256-bit descriptors by Hamming distance under the named thresholds, and
// (where asked) keeps only matches whose orientation change agrees with the dominant ones
// (rotation histogram). Each is an adapter from map objects to the kernels of
// features/matcher.hpp (nearestTwo over a grid window or a shared vocabulary node,
// bestEpipolarPartner, RotationHistogram); matchLocalPoints runs its searchByProjection.
// Callers hold Map::mutex(). Results are deterministic: candidates are visited in index/id order
// and ties keep the first. Bodies: map_matching_impl.hpp, compiled where the pipeline is
// instantiated. Loop closing's keyframe-to-keyframe searches are in keyframe_matching.hpp,
// beside these, below every thread module.
#pragma once

#include <set>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "orbis/camera/fisheye_plane_camera.hpp"
#include "orbis/features/matcher.hpp"  // the search kernels, kThHigh, kThLow, RotationHistogram
#include "orbis/map/map.hpp"
#include "orbis/map/frame.hpp"

namespace orbis::matching {

// Where a map point should appear in a frame, if it is in the frustum and within its
// scale-invariance distance range and viewed at less than 60° from its mean direction.
struct Projection {
  // @{
  // Predicted pixel and right coordinate (−1: none).
  float u = 0, v = 0, uRight = -1;
  // @}
  // Predicted pyramid level.
  int level = 0;
  // Cosine between the ray and the point's mean viewing direction.
  float viewCos = 1;
  // The matching window's widening by the camera's lens there (searchWindowStretch).
  float windowStretch = 1;
};
// Predicts where a map point appears in a frame at pose Tcw (camera centre cameraCentre, i.e.
// Tcw.inverse().translation(), passed in because callers project hundreds of points from one
// pose); false outside the frustum, the distance range or 60° of the mean direction.
template <CameraModel Camera>
bool projectIntoFrame(const Camera& camera, const MapIntrinsics& bounds, const MapPoint& point, const SE3d& Tcw,
                      const Eigen::Vector3d& cameraCentre, const ScaleLevels& levels, Projection& out);

// Motion model: points of the last frame re-projected into the current frame (already posed
// by the prediction), within `radius` × level scale. Stereo frames also constrain the level by
// the forward/backward motion. Returns the number of new matches.
template <CameraModel Camera>
int matchFromLastFrame(Frame<Camera>& current, const Frame<Camera>& last, float radius, bool checkOrientation);

// Local map: candidate points (with their projections) searched in the frame; the window grows
// with the level and for oblique views. Skips keypoints already matched.
template <CameraModel Camera>
int matchLocalPoints(Frame<Camera>& frame, const std::vector<MapPoint*>& points, const std::vector<Projection>& projections,
                     float radiusFactor, float ratio = 0.8f);

// Bag-of-words guided matching between a keyframe's map points and a frame's keypoints that fall
// in the same vocabulary node. Writes matches into `out` (one slot per frame keypoint).
template <CameraModel Camera>
int matchByBow(const KeyFrame& kf, const Frame<Camera>& frame, std::vector<MapPoint*>& out, float ratio, bool checkOrientation);

// Relocalisation: a keyframe's points projected into a posed frame, skipping `alreadyFound`.
template <CameraModel Camera>
int matchFromKeyFrame(Frame<Camera>& frame, const KeyFrame& kf, const std::set<MapPoint*, ById>& alreadyFound, float radius,
                      int maxDistance);

// Pairs of unmatched keypoints (i in kf1, j in kf2) agreeing with the epipolar geometry F12
// (x2ᵀ F12 x1 = 0 convention: F maps kf1 points to lines in kf2), for triangulation.
template <CameraModel Camera>
std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulation(const Camera& camera, const KeyFrame& kf1,
                                                                      const KeyFrame& kf2, const Eigen::Matrix3d& F12,
                                                                      bool onlyStereo);

// Projects `points` into `kf`; where a keypoint matches, either adds the observation or keeps
// the better-observed of the two duplicate points. Returns the number of fused points.
template <CameraModel Camera>
int fuse(const Camera& camera, KeyFrame& kf, const std::vector<MapPoint*>& points, float radius = 3.0f);

}  // namespace orbis::matching

#include "orbis/map/map_matching_impl.hpp"
