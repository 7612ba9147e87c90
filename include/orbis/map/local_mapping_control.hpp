// orbis/map/local_mapping_control.hpp — what tracking and loop closing ask of local mapping.
//
// Contract: the paper's threads talk through this seam, not through each other's headers:
// tracking hands keyframes over and asks whether mapping accepts more (and may interrupt its
// local BA); loop closing stops mapping while it corrects the map and releases it afterwards.
// LocalMapper<Sensor> implements it; every call is safe from any thread.
#pragma once

#include <cstddef>

#include "orbis/map/key_frame.hpp"

namespace orbis {

// Stereo/RGB-D tracking makes a keyframe while mapping is busy only while fewer than this many
// wait (ORB-SLAM2's rule).
inline constexpr std::size_t kMaxQueuedKeyFrames = 3;

// What tracking and loop closing may ask of local mapping, so neither includes mapping/ (the layer
// rule).
class LocalMappingControl {
 public:
  virtual ~LocalMappingControl() = default;

  // Tracking (map mutex held): queue a new keyframe.
  virtual void insertKeyFrame(KeyFrame* kf) = 0;
  // Keyframes waiting.
  virtual std::size_t queuedKeyFrames() const = 0;
  // False while mapping is busy with the keyframes it has.
  virtual bool acceptsKeyFrames() const = 0;
  // Stops a running local BA at its next iteration.
  virtual void interruptBundleAdjustment() = 0;

  // Loop closing pauses local mapping while it corrects the map.
  virtual void requestStop() = 0;
  // @{
  // Whether mapping has stopped, or is stopping, for loop closing.
  virtual bool isStopped() const = 0;
  virtual bool isStoppedOrStopping() const = 0;
  // @}
  // While set, a stop request is not honoured (tracking is creating a keyframe). Returns false
  // when mapping is already stopped.
  virtual bool setNotStop(bool flag) = 0;
  // Lets stopped mapping go on.
  virtual void release() = 0;
};

}  // namespace orbis
