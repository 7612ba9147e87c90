// src/viewer/map_delta.hpp — the map messages LiveViewer streams: changes, not whole maps.
//
// Contract: MapDeltaEncoder keeps the scene as the pages were sent it (points with position, first
// keyframe and local-map flag; keyframes with pose and edges; the trajectory; the loop closures)
// and numbers its messages 1, 2, ... encode(map, localMap, live) compares a new snapshot with that
// scene, makes the snapshot the scene and returns the next message: only what changed since the
// previous one, so messages 1..n applied in order to an empty scene give the map of message n.
// full() returns the whole current scene as one message numbered like the newest delta, for a
// page that joins late or missed a delta. A point or keyframe whose position moved by at most
// kMoveTolerance is not sent again (what the page shows stays within it of the map). encode()
// and full() may be called from different threads.
//
// Message JSON: {"seq","full","live","frames",
//   "keyFrames":[{"id","frame","parent","map","Twc":[12, row-major 3x4],"covisibles":[ids],"loops":[ids]}],
//   "removedKeyFrames":[ids],"points":[id,x,y,z,firstKeyFrame,inLocalMap,...],"removedPoints":[ids],
//   "trajectoryFrom":i,"trajectory":[x,y,z,... of cameras i, i+1, ...],"trajectoryLength":n,
//   "loopClosures":[{"current","loop","frame","inliers"}] (all of them),
//   "merges":[{"frame","kept","moved","inliers"}] (maps of the atlas merged, all of them)}
// keyFrames and points: new or changed ones (all of them in a full message); the page replaces
// its trajectory from camera trajectoryFrom on. Camera coordinates as orbis keeps them (x right,
// y down, z forward), metres, 4 decimals.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "orbis/viewer/slam_observer.hpp"

namespace orbis::viewer_detail {

class MapDeltaEncoder {
 public:
  // 1 mm (or a thousandth of a monocular map's unit, about its first scene depth): invisible in
  // the view, while bundle adjustment moves thousands of points by less on every keyframe.
  static constexpr double kMoveTolerance = 1e-3;

  struct Message {
    std::uint64_t seq = 0;
    std::string json;
  };

  Message encode(const MapSnapshot& map, const std::unordered_set<MapPointId>& localMap, bool live);
  Message full() const;

 private:
  struct SentPoint {
    Eigen::Vector3f position;
    KeyFrameId firstKeyFrame = 0;
    bool local = false;
    std::uint64_t seenIn = 0;  // the message whose snapshot held it last
  };
  struct SentKeyFrame {
    KeyFrameSnapshot keyFrame;
    std::uint64_t seenIn = 0;
  };

  mutable std::mutex mutex_;
  std::uint64_t seq_ = 0;
  bool live_ = true;
  std::size_t frames_ = 0;
  std::unordered_map<MapPointId, SentPoint> points_;
  std::map<KeyFrameId, SentKeyFrame> keyFrames_;
  std::vector<Eigen::Vector3f> trajectory_;
  std::vector<LoopClosureEvent> loopClosures_;
  std::vector<MapMergeEvent> merges_;
};

}  // namespace orbis::viewer_detail
