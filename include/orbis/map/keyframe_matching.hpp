// orbis/map/keyframe_matching.hpp — the keyframe-to-keyframe descriptor searches of loop closing
// (ORB-SLAM §VII-B, C), beside map_matching.hpp in the matching layer below the thread modules.
//
// Contract: every search compares 256-bit ORB descriptors by Hamming distance between a keyframe
// and map points or another keyframe, writes its matches into one slot per keypoint of the
// first keyframe (null when unmatched) and returns how many slots it filled. Callers hold
// Map::mutex(). Candidates are visited in index order and ties keep the first, so results are
// deterministic. Like map_matching.hpp's, these are adapters over the kernels of
// features/matcher.hpp (nearestTwo, RotationHistogram).
//  - matchKeyFramesByBow: keyframe-to-keyframe, both keypoints owning map points, candidates
//    grouped by vocabulary node, best distance ≤ TH_LOW and < ratio × second best, rotation
//    consistency.
//  - matchByRelativePose: with T12 (camera 1 from camera 2), the points of each keyframe are
//    projected into the other; a pair is kept when both directions agree (ORB-SLAM's
//    SearchBySim3 with the scale fixed to 1). Existing matches in `matches12` are kept.
//  - matchBySim3: the same with a similarity S12 (monocular maps: camera 2's map scale taken to
//    camera 1's); each point's scale-invariance range is checked in its own map's units.
//  - matchByProjection: `points` projected into keyframe `kf` at pose Tcw (which may differ from
//    kf.Tcw(): the loop-corrected pose), skipping points already matched in `matches`.
#pragma once

#include <vector>

#include "orbis/camera/camera_model.hpp"
#include "orbis/camera/fisheye_plane_camera.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/map/map.hpp"

namespace orbis::matching {

// Matches the map points of kf1 to keypoints of kf2 sharing a vocabulary node (loop closing's first
// search); returns the count.
int matchKeyFramesByBow(const KeyFrame& kf1, const KeyFrame& kf2, std::vector<MapPoint*>& matches12,
                        float ratio = 0.75f);

// Projections go through `camera`'s pinhole (both keyframes share the sensor's camera).
template <CameraModel Camera>
int matchByRelativePose(const Camera& camera, const KeyFrame& kf1, const KeyFrame& kf2, const SE3d& T12,
                        std::vector<MapPoint*>& matches12, float radius = 7.5f);

// Matches points of each keyframe projected into the other through the similarity S12 (loop
// closing's guided search).
template <CameraModel Camera>
int matchBySim3(const Camera& camera, const KeyFrame& kf1, const KeyFrame& kf2, const Sim3d& S12,
                std::vector<MapPoint*>& matches12, float radius = 7.5f);

// Matches points projected into keyframe kf at pose Tcw, within radius pixels (loop fusion).
template <CameraModel Camera>
int matchByProjection(const Camera& camera, const KeyFrame& kf, const SE3d& Tcw, const std::vector<MapPoint*>& points,
                      std::vector<MapPoint*>& matches, float radius = 10.0f);

}  // namespace orbis::matching

#include "orbis/map/keyframe_matching_impl.hpp"
