// orbis/map/map_point.hpp — a 3-D landmark of the sparse map (paper §III; ORB-SLAM §III-C).
//
// Contract: a MapPoint stores its world position, the keyframes that observe it (ordered by
// keyframe id, so every iteration is deterministic), the mean viewing direction, the most
// distinctive descriptor among its observations and the distance range over which ORB's
// scale invariance lets it be seen. All mutable members are guarded by the owning
// Map::mutex(): lock it before calling anything that reads or changes them. Points are never
// deleted while the map lives; culling marks them bad (and may name a replacement).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "orbis/features/descriptor.hpp"

namespace orbis {

class KeyFrame;
// @{
// Ids of keyframes and map points.
using KeyFrameId = std::uint64_t;
using MapPointId = std::uint64_t;
// @}

// Orders pointers to keyframes or map points by id, so containers iterate reproducibly.
struct ById {
  // Compares by id.
  template <class T>
  bool operator()(const T* a, const T* b) const { return a->id < b->id; }
};

// The keyframes observing a map point, each with the index of its keypoint, in keyframe-id
// order: a sorted vector rather than a std::map, because tracking walks every matched point's
// observations each frame and a node-based tree made that walk a quarter of the local-map update
// (docs/notes/2026-11-27-speed-mapping-cpu.md). Read-only outside MapPoint.
class ObservationList {
 public:
  // @{
  // The (keyframe, keypoint index) pairs in keyframe-id order.
  using value_type = std::pair<KeyFrame*, std::size_t>;
  using const_iterator = std::vector<value_type>::const_iterator;
  const_iterator begin() const { return entries_.begin(); }
  const_iterator end() const { return entries_.end(); }
  // @}
  // @{
  // Number of observations, and whether there is none.
  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  // @}

 private:
  friend class MapPoint;
  // Index of the entry of keyframe id `id`, or size() when there is none.
  std::size_t find(KeyFrameId id) const;
  // Adds (kf, index) in id order; false when kf already observes.
  bool insert(KeyFrame* kf, KeyFrameId id, std::size_t index);
  // Removes entry k (from find).
  void erase(std::size_t k);
  void clear();
  std::vector<value_type> entries_;
  std::vector<KeyFrameId> ids_;  // entries_[k].first->id, searched without touching the keyframes
};

// A 3-D map point: position, observations by keyframes, mean viewing direction, scale-invariance
// distances and representative descriptor (§III-C).
class MapPoint {
 public:
  // Made by Map::createMapPoint.
  MapPoint(MapPointId id, const Eigen::Vector3d& position, KeyFrame* reference, KeyFrameId firstKeyFrame,
           std::uint64_t firstFrame)
      : id(id), firstKeyFrame(firstKeyFrame), firstFrame(firstFrame), position_(position), reference_(reference) {}

  // Unique, increasing with creation.
  const MapPointId id;
  const KeyFrameId firstKeyFrame;  // keyframe that created it
  const std::uint64_t firstFrame;  // index of the frame that created it

  // @{
  // World position (read and set), mean viewing direction, representative descriptor.
  const Eigen::Vector3d& position() const { return position_; }
  void setPosition(const Eigen::Vector3d& p) { position_ = p; }
  const Eigen::Vector3d& normal() const { return normal_; }
  const OrbDescriptor& descriptor() const { return descriptor_; }
  // @}
  // For points without observations (tracking's temporary visual-odometry points).
  void setDescriptor(const OrbDescriptor& d) { descriptor_ = d; }
  // The keyframe its distances are measured from.
  KeyFrame* reference() const { return reference_; }

  // keyframe -> index of the keypoint in that keyframe.
  const ObservationList& observations() const { return observations_; }
  // Observation count as ORB-SLAM counts it: a stereo observation counts twice.
  int observationCount() const { return observationCount_; }
  // Whether kf observes it.
  bool isObservedBy(const KeyFrame* kf) const;
  long indexIn(const KeyFrame* kf) const;  // -1 when not observed

  // Records that keypoint index of kf observes it.
  void addObservation(KeyFrame* kf, std::size_t index);
  // Removes the observation; marks the point bad when two or fewer remain. Returns true if it
  // turned bad.
  bool eraseObservation(KeyFrame* kf);

  // Whether it was culled or replaced.
  bool isBad() const { return bad_; }
  // Detaches the point from every keyframe and marks it bad.
  void setBad();
  // Moves all observations of this point to `other` (which survives) and marks this one bad,
  // recording the replacement so late readers can follow it.
  void replaceWith(MapPoint* other);
  // The point it was fused into, if any.
  MapPoint* replacement() const { return replacedBy_; }

  // Tracking statistics: frames in whose frustum it fell, and frames that matched it.
  void increaseVisible(int n = 1) { visible_ += n; }
  // @{
  // Tracking statistics: counts and their ratio (culling asks for 25 %).
  void increaseFound(int n = 1) { found_ += n; }
  int visible() const { return visible_; }
  int found() const { return found_; }
  float foundRatio() const { return static_cast<float>(found_) / static_cast<float>(visible_); }
  // @}

  // @{
  // Per-frame marks of the tracker (guarded by the map mutex like the rest): the frame, plus one,
  // whose local map last listed the point and whose matches last held it. They replace sets
  // rebuilt every frame.
  std::uint64_t inLocalMapOf = 0, matchedIn = 0;
  // @}

 private:
  // Here, on the marks' cache line: tracking reads the three together for every local point.
  bool bad_ = false;

 public:

  // Recomputes the representative descriptor: the observation with least median distance to
  // the others.
  void computeDistinctiveDescriptor();
  // Recomputes the mean viewing direction and the scale-invariance distance range from the
  // reference keyframe's observation.
  void updateNormalAndDepth();
  // @{
  // Nearest and farthest distance at which it can be matched.
  float minDistanceInvariance() const { return 0.8f * minDistance_; }
  float maxDistanceInvariance() const { return 1.2f * maxDistance_; }
  // @}
  // Pyramid level at which the point should appear from `distance` (ORB-SLAM's PredictScale).
  int predictScale(float distance, int levels, float logScaleFactor) const;

 private:
  Eigen::Vector3d position_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  OrbDescriptor descriptor_;
  float minDistance_ = 0, maxDistance_ = 0;
  KeyFrame* reference_;
  ObservationList observations_;
  int observationCount_ = 0;
  int visible_ = 1, found_ = 1;
  MapPoint* replacedBy_ = nullptr;
};

}  // namespace orbis
