// orbis/map/map.hpp — the map: owner of every keyframe and map point, and its lock.
//
// Contract: Map creates keyframes and points (ids increase from 0 in creation order) and never
// frees them while it lives — culled objects are only marked bad — so raw pointers handed out
// stay valid for the map's lifetime. One mutex, mutex(), guards every mutable member of the map,
// its keyframes and its points: the tracking, local-mapping and loop-closing threads each hold
// it for one step at a time and run their optimisations on copies, outside it. Listings come
// ordered by id, which keeps deterministic mode deterministic.
#pragma once

#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "orbis/map/key_frame.hpp"
#include "orbis/map/map_point.hpp"

namespace orbis {

// The map: owns every keyframe and map point (bad ones too, so pointers stay valid), guarded by one
// mutex.
class Map {
 public:
  Map() = default;
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  // The map's mutex: held by whoever reads or changes keyframes, points or graphs.
  std::mutex& mutex() const { return mutex_; }

  // Creates a keyframe with the next id.
  KeyFrame* createKeyFrame(std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                           std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                           bow::BowVector bowVector, bow::FeatureVector featureVector);
  // Creates a map point with the next id.
  MapPoint* createMapPoint(const Eigen::Vector3d& position, KeyFrame* reference, std::uint64_t frameIndex);

  // Good keyframes and points, ordered by id.
  std::vector<KeyFrame*> keyFrames() const;
  // @{
  // Good map points, ordered by id, and the counts of good keyframes and points.
  std::vector<MapPoint*> mapPoints() const;
  std::size_t keyFrameCount() const;
  std::size_t mapPointCount() const;
  // @}
  // @{
  // A keyframe or point by id (null beyond the last), and how many were ever created.
  KeyFrame* keyFrame(KeyFrameId id) const { return id < keyFrames_.size() ? keyFrames_[id].get() : nullptr; }
  MapPoint* mapPoint(MapPointId id) const { return id < points_.size() ? points_[id].get() : nullptr; }
  std::size_t createdKeyFrames() const { return keyFrames_.size(); }
  std::size_t createdMapPoints() const { return points_.size(); }
  // @}

  // The first keyframe (the gauge of full BA and the root of the spanning tree).
  KeyFrame* origin() const { return keyFrames_.empty() ? nullptr : keyFrames_.front().get(); }

 private:
  mutable std::mutex mutex_;
  std::vector<std::unique_ptr<KeyFrame>> keyFrames_;  // index == id
  std::vector<std::unique_ptr<MapPoint>> points_;     // index == id
};

}  // namespace orbis
