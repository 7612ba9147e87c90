// orbis/map/slam_events.hpp — the plain outcome records the threads report and observers read:
// a frame's tracking state, what became of each keypoint, and a loop closure.
//
// Contract: value types only, with no behaviour, kept below the thread modules so that a
// display (viewer/) can read them without including tracking/ or loop/.
#pragma once

#include <cstdint>

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

}  // namespace orbis
