// orbis/map/slam_events.hpp — the plain outcome records the threads report and observers read:
// a frame's tracking state, what became of each keypoint, a loop closure and a merge of two maps
// of the atlas.
//
// Contract: value types only, with no behaviour, kept below the thread modules so that a
// display (viewer/) can read them without including tracking/ or loop/.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "orbis/map/map_point.hpp"

namespace orbis {

// Tracking's state after a frame.
enum class TrackingState { NotInitialised, Ok, Lost };
// "not-initialised", "ok" or "lost".
const char* toString(TrackingState s);

// What became of one keypoint of the last frame: matched to a map point, the seed of a new map
// point (a new keyframe's or the first map's), rejected by motion-only BA, or left unmatched.
enum class KeypointState : std::uint8_t { Unmatched, Matched, New, Outlier };

// A loop closure, as reports list it.
struct LoopClosureEvent {
  // @{
  // The current keyframe and the keyframe it closed the loop with.
  KeyFrameId current = 0, loop = 0;
  // @}
  std::uint64_t frameIndex = 0;  // frame the current keyframe was made from
  int inliers = 0;               // matched points after the projection search
  // The similarity's scale: the current keyframe's map scale over the loop keyframe's, i.e. the
  // scale drift the loop corrects (1 for metric sensors).
  double scale = 1.0;
};

// Two maps of the atlas merged (issue 32): a keyframe of the active map recognised a place of
// another map; the smaller map was moved into the other's frame (x_kept = s·R·x_moved + t) and
// relabelled as it.
struct MapMergeEvent {
  // @{
  // The active map's keyframe and the other map's keyframe it matched.
  KeyFrameId current = 0, other = 0;  // the active map's keyframe and the other map's it matched
  // @}
  std::uint64_t frameIndex = 0;       // frame the current keyframe was made from
  std::uint64_t otherFrameIndex = 0;  // frame the other map's keyframe was made from
  // @{
  // The active map and the other map.
  std::uint32_t activeMap = 0, otherMap = 0;
  // @}
  // @{
  // The map moved into the other's frame, and the map kept.
  std::uint32_t movedMap = 0, keptMap = 0;
  // @}
  // @{
  // Keyframes and points moved.
  std::size_t movedKeyFrames = 0, movedPoints = 0;
  // @}
  int inliers = 0;                  // matched points after the projection search
  int fusedPoints = 0;              // duplicated points fused across the seam
  Eigen::Vector4d rotation{1, 0, 0, 0};  // the move's rotation as a quaternion (w, x, y, z)
  // The move's translation.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;               // 1 for metric sensors
  double milliseconds = 0;          // spent merging, essential graph and welding BA included
};

// One map of the atlas as the system reports it.
struct AtlasMapInfo {
  // The map's id.
  std::uint32_t id = 0;
  // @{
  // Its good keyframes and points.
  std::size_t keyFrames = 0, mapPoints = 0;
  // @}
  // The frame that opened it.
  std::uint64_t startFrame = 0;
  // Whether it is the active map.
  bool active = false;
  bool merged = false;              // merged into mergedInto (its keyframes now belong there)
  // The map it was merged into (when merged).
  std::uint32_t mergedInto = 0;
};

}  // namespace orbis
