// orbis/map/map_bundle_adjustment.hpp — local and full BA over the map (paper §III-C), shared by
// local mapping and loop closing.
//
// Contract: localBundleAdjustment optimises the keyframe, its covisible keyframes and every point
// they see, with the other keyframes observing those points fixed; two passes, the second without
// the χ² outliers, which are then removed from the map. It copies the problem out of the map
// under Map::mutex(), solves outside it (abortable through `abort`) and writes back under the
// lock, skipping objects that went bad meanwhile. fullBundleAdjustment does the same over every
// keyframe and point of one map of the atlas, its root fixed, and returns the optimised values without writing them:
// the loop closer merges them through the spanning tree. Both run on the sensor's camera model and
// robust kernel (callers pass Sensor::Camera and Sensor::RobustKernel): depth observations of an RGB-D sensor as
// a whitened disparity, of a stereo pair as (uL, v, uR). `threads` share the solver's Schur
// complement (optim/solver_options.hpp): bit-identical results at any count.
// Bodies: map_bundle_adjustment_impl.hpp.
#pragma once

#include <atomic>
#include <map>

#include "orbis/map/map.hpp"
#include "orbis/camera/camera_model.hpp"
#include "orbis/optim/robust_kernel.hpp"

namespace orbis {

// What a local BA did (orbis run --stats).
struct LocalBundleAdjustmentStats {
  // @{
  // Keyframes optimised, fixed keyframes, points, observations, and outliers removed.
  int keyFrames = 0, fixedKeyFrames = 0, points = 0, observations = 0, outliersRemoved = 0;
  // @}
  int iterations = 0;  // of both passes
  // Whether the next keyframe stopped it.
  bool aborted = false;
  // @{
  // Stereo cameras: mean measured minus BA-predicted disparity (px) of the inlier stereo matches,
  // near and far (diagnosis of a disparity bias; far ones are monocular in BA, so unpulled).
  double closeDisparityBias = 0, farDisparityBias = 0;
  // @}
  // @{
  // Close and far stereo matches counted.
  int closeStereo = 0, farStereo = 0;
  // @}
};

// ORB-SLAM's local BA around keyframe kf (it and its covisible keyframes, their points; the other
// observers fixed), on the sensor's camera and kernel; abort stops it.
template <optim::RobustKernel Kernel, CameraModel Camera>
LocalBundleAdjustmentStats localBundleAdjustment(const Camera& camera, Map& map, KeyFrame* kf,
                                                 std::atomic<bool>* abort, int threads = 2);

// The result of a full BA, applied by loop closing once it ends.
struct FullBundleAdjustmentResult {
  std::map<KeyFrameId, SE3d> keyFramePoses;            // Tcw of every optimised keyframe
  std::map<MapPointId, Eigen::Vector3d> pointPositions;  // world positions
  // Whether it was stopped.
  bool aborted = false;
};

// Full BA over every keyframe and point, the first keyframe fixed.
template <optim::RobustKernel Kernel, CameraModel Camera>
FullBundleAdjustmentResult fullBundleAdjustment(const Camera& camera, Map& map, int iterations,
                                                std::atomic<bool>* abort, std::uint32_t mapId = 0, int threads = 2);

}  // namespace orbis

#include "orbis/map/map_bundle_adjustment_impl.hpp"
