// orbis/mapping/bundle_adjustment.hpp — local and full BA over the map (paper §III-C).
//
// Contract: localBundleAdjustment optimises the keyframe, its covisible keyframes and every point
// they see, with the other keyframes observing those points fixed; two passes, the second without
// the χ² outliers, which are then removed from the map. It copies the problem out of the map
// under Map::mutex(), solves outside it (abortable through `abort`) and writes back under the
// lock, skipping objects that went bad meanwhile. fullBundleAdjustment does the same over every
// keyframe and point, the origin fixed, and returns the optimised values without writing them:
// the loop closer merges them through the spanning tree.
#pragma once

#include <atomic>
#include <map>

#include "orbis/map/map.hpp"

namespace orbis {

struct LocalBundleAdjustmentStats {
  int keyFrames = 0, fixedKeyFrames = 0, points = 0, observations = 0, outliersRemoved = 0;
  bool aborted = false;
};

LocalBundleAdjustmentStats localBundleAdjustment(Map& map, KeyFrame* kf, std::atomic<bool>* abort);

struct FullBundleAdjustmentResult {
  std::map<KeyFrameId, SE3d> keyFramePoses;            // Tcw of every optimised keyframe
  std::map<MapPointId, Eigen::Vector3d> pointPositions;  // world positions
  bool aborted = false;
};

FullBundleAdjustmentResult fullBundleAdjustment(Map& map, int iterations, std::atomic<bool>* abort);

}  // namespace orbis
