// orbis/map/map.hpp — the map: owner of every keyframe and map point, and its lock.
//
// Contract: Map creates keyframes and points (ids increase from 0 in creation order) and never
// frees them while it lives — culled objects are only marked bad — so raw pointers handed out
// stay valid for the map's lifetime. One mutex, mutex(), guards every mutable member of the map,
// its keyframes and its points: the tracking, local-mapping and loop-closing threads each hold
// it for one step at a time and run their optimisations on copies, outside it. Listings come
// ordered by id, which keeps deterministic mode deterministic.
//
// The atlas (issue 32): the container holds several maps, each a set of keyframes (and the points
// they made) with its own frame of reference, told apart by KeyFrame::mapId(). Keyframes and
// points share one id space and one mutex, so a merge only relabels and moves objects. New
// keyframes join the active map; startNewMap() opens an empty one and makes it active; mergeInto
// relabels one map's keyframes as another's. Maps never share a covisibility edge until merged.
#pragma once

#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "orbis/map/key_frame.hpp"
#include "orbis/map/map_point.hpp"

namespace orbis {

// One map of the atlas, as the container records it.
struct AtlasMapRecord {
  // The map's id.
  std::uint32_t id = 0;
  std::uint64_t startFrame = 0;             // the frame that opened it (0 for the first map)
  std::optional<std::uint32_t> mergedInto;  // set once it has been merged into another map
};

// One merge, in the order they happened: map `from` was moved into `into`'s frame by a transform
// x_into = scale·R·x_from + t (scale 1 for metric sensors) and relabelled as it.
struct AtlasMerge {
  // @{
  // The moved map, the kept map and the move's scale.
  std::uint32_t from = 0;
  std::uint32_t into = 0;
  double scale = 1;
  // @}
};

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
  // Creates a keyframe with the next id whose bag of words computeBow fills when first needed.
  KeyFrame* createKeyFrame(std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
                           std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
                           BowComputation computeBow);
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

  // ---- the atlas (caller holds mutex()) ---------------------------------------------------
  // @{
  // The active map's id, read and set.
  std::uint32_t activeMapId() const { return active_; }
  void setActiveMap(std::uint32_t id) { active_ = id; }
  // @}
  // Opens an empty map, made active; returns its id.
  std::uint32_t startNewMap(std::uint64_t frameIndex);
  // Every map ever opened, merged ones included, by id.
  const std::vector<AtlasMapRecord>& mapRecords() const { return records_; }
  // @{
  // Good keyframes and points of one map, ordered by id (a point belongs to its reference
  // keyframe's map).
  std::vector<KeyFrame*> keyFrames(std::uint32_t mapId) const;
  std::vector<MapPoint*> mapPoints(std::uint32_t mapId) const;
  std::size_t keyFrameCount(std::uint32_t mapId) const;
  std::size_t mapPointCount(std::uint32_t mapId) const;
  // @}
  // Relabels every keyframe (bad ones too) of map `from` as map `into`'s; `from`'s root stops
  // being a BA gauge. Poses are the caller's business (they must already be in into's frame,
  // moved by a transform of this scale: a tracker rescales what it keeps relative to them).
  void mergeInto(std::uint32_t from, std::uint32_t into, double scale = 1);
  // How many merges have happened: a tracker that sees it change re-reads its last pose.
  std::uint64_t mergeCount() const { return merges_.size(); }
  // Every merge of this session, in order (not saved in map files).
  const std::vector<AtlasMerge>& merges() const { return merges_; }
  // Whether frames tracked in map `trackedIn` now belong to map `mapId` (the same map, or one
  // that map was merged into, directly or through others).
  bool mapLeadsTo(std::uint32_t trackedIn, std::uint32_t mapId) const;
  // Map files: restores the records (ids 0..count-1) and the active map after loading.
  void restoreAtlas(std::vector<AtlasMapRecord> records, std::uint32_t active);

 private:
  // Takes a new keyframe in: its map and, for a map's first, the root mark.
  KeyFrame* adopt(std::unique_ptr<KeyFrame> created);

  mutable std::mutex mutex_;
  std::vector<std::unique_ptr<KeyFrame>> keyFrames_;  // index == id
  std::vector<std::unique_ptr<MapPoint>> points_;     // index == id
  std::vector<AtlasMapRecord> records_{AtlasMapRecord{}};  // index == map id
  std::vector<char> hasKeyFrame_{0};                       // per map: its root exists
  std::uint32_t active_ = 0;
  std::vector<AtlasMerge> merges_;
};

}  // namespace orbis
