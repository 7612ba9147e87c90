// orbis/map/key_frame.hpp — a keyframe: a frame kept in the map (paper §III; ORB-SLAM §III-B).
//
// Contract: a KeyFrame owns an immutable copy of its frame's features (keypoints, descriptors,
// stereo coordinate, grid), its bag-of-words vectors, and — guarded by the owning
// Map::mutex() — its pose, its map-point associations (one slot per keypoint, null when
// unmatched), its covisibility edges (weight = shared map points, edges kept from 15) and its
// place in the spanning tree. Sensor-agnostic: the stereo/RGB-D coordinate uR is < 0 for a
// monocular keypoint, and the few camera numbers the map needs travel in MapIntrinsics.
#pragma once

#include <bit>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "orbis/bow/bow_vector.hpp"
#include "orbis/camera/camera_model.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/map/map_point.hpp"

namespace orbis {

// The camera a keyframe was taken with, as the map file records it: pinhole intrinsics of the
// (undistorted, rectified) left image, the stereo/RGB-D baseline times fx (0 for monocular),
// the close/far depth threshold and the image bounds keypoints may fall in. The pipeline reads
// only the bounds (inImage); it projects through the sensor's compile-time camera model.
struct MapIntrinsics {
  // @{
  // Pinhole intrinsics of the (undistorted, rectified) left image.
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // @}
  double bf = 0;          // baseline × fx; 0 for a monocular camera
  double closeDepth = 0;  // depth below which a stereo keypoint is "close" (40 × baseline)
  // A depth sensor's σ of the virtual disparity bf/d (px at level 0); 0 for a stereo pair. It
  // picks the residual BA gives the keypoint's depth (optim/reprojection.hpp).
  double disparitySigma = 0;
  // @{
  // The image bounds keypoints may fall in (undistorted pixels).
  double minX = 0, maxX = 0, minY = 0, maxY = 0;
  // @}

  // Whether (u, v) lies inside the bounds.
  bool inImage(double u, double v) const { return u >= minX && u < maxX && v >= minY && v < maxY; }
};

// World point of keypoint i of `features` from its depth (stereo or RGB-D), seen from the pose
// Tcw; false for a keypoint without depth. Frames and keyframes both lift points through it.
template <CameraModel Camera>
bool pointFromDepth(const Camera& camera, const FrameFeatures& features, std::size_t i, const SE3d& Tcw,
                    Eigen::Vector3d& world) {
  const float z = features.depth[i];
  if (!(z > 0)) return false;
  const Keypoint& k = features.keypointsUn[i];
  world = Tcw.inverse() * camera.unproject(Eigen::Vector2d(k.u, k.v), static_cast<double>(z));
  return true;
}

// Fills a keyframe's bag of words from its features. Tracking hands one to a keyframe instead of
// the vectors, so the vocabulary lookup runs on the mapping thread (as in ORB-SLAM2) rather than
// on the camera's critical path (docs/notes/2026-11-27-speed.md).
using BowComputation = std::function<void(const FrameFeatures&, bow::BowVector&, bow::FeatureVector&)>;

// A keyframe: an immutable frame (features, bag of words), its pose, its map points and its place
// in the covisibility graph, the spanning tree and the loop edges (§III-B).
class KeyFrame {
 public:
  static constexpr int kCovisibilityThreshold = 15;  // shared points for an edge (ORB-SLAM)

  // Made by Map::createKeyFrame.
  KeyFrame(KeyFrameId id, std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
           std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
           bow::BowVector bowVector, bow::FeatureVector featureVector);
  // Made by Map::createKeyFrame, the bag of words computed by computeBow when first needed.
  KeyFrame(KeyFrameId id, std::uint64_t frameIndex, double timestamp, const SE3d& Tcw,
           std::shared_ptr<const FrameFeatures> features, const MapIntrinsics& intrinsics,
           BowComputation computeBow);

  // Unique, increasing with creation.
  const KeyFrameId id;
  const std::uint64_t frameIndex;  // index of the frame it was made from
  // Seconds.
  const double timestamp;
  // Its camera, as the map file records it.
  const MapIntrinsics intrinsics;

  // ---- immutable frame data --------------------------------------------------------------
  // The frame's features (immutable).
  const FrameFeatures& features() const { return *features_; }
  // @{
  // Keypoints, the bag of words and the node-grouped features (computed on first use when the
  // keyframe was made with a BowComputation; any thread, no lock needed).
  std::size_t size() const { return points_.size(); }
  const bow::BowVector& bowVector() const { ensureBow(); return bow_; }
  const bow::FeatureVector& featureVector() const { ensureBow(); return featureVector_; }
  // @}
  // Computes the bag of words now if it was left for later; once, whichever thread comes first.
  void ensureBow() const;

  // ---- pose (camera-from-world) ------------------------------------------------------------
  // Camera from world.
  const SE3d& Tcw() const { return Tcw_; }
  // @{
  // World from camera, the camera centre, and setting the pose.
  SE3d Twc() const { return Tcw_.inverse(); }
  Eigen::Vector3d cameraCenter() const { return Tcw_.inverse().translation(); }
  void setPose(const SE3d& Tcw) { Tcw_ = Tcw; }
  // @}

  // ---- map-point associations ----------------------------------------------------------
  // The map point of keypoint i, or null.
  MapPoint* point(std::size_t i) const { return points_[i]; }
  // @{
  // The map point of each keypoint (null: none); setting and erasing them.
  const std::vector<MapPoint*>& points() const { return points_; }
  void setPoint(std::size_t i, MapPoint* p) {
    points_[i] = p;
    markSlot(i, p != nullptr);
  }
  void erasePoint(std::size_t i) {
    points_[i] = nullptr;
    markSlot(i, false);
  }
  void erasePoint(const MapPoint* p);
  // @}
  // Calls f(p) for every non-null slot's point, in slot order. It walks a bit per slot rather
  // than the slots: most slots are null, and a branch on each mispredicted often enough to cost
  // tracking's local-map update a third of its time (docs/notes/2026-11-29-speed-slot-bits.md).
  template <class F>
  void forEachPoint(F&& f) const {
    forEachOccupiedSlot([&](std::size_t i) { f(points_[i]); });
  }
  // Map points with at least minObservations observations (ORB-SLAM's TrackedMapPoints).
  int trackedPoints(int minObservations) const;
  // Distinct good map points, ordered by id.
  std::vector<MapPoint*> goodPoints() const;

  // ---- covisibility graph -------------------------------------------------------------
  // Recomputes this keyframe's edges from its map points, updates the neighbours' edges, and,
  // the first time, attaches it to the spanning tree under its strongest neighbour.
  void updateConnections();
  // @{
  // Covisibility edges: add, erase, and the weight (shared points) to a keyframe.
  void addConnection(KeyFrame* kf, int weight);
  void eraseConnection(KeyFrame* kf);
  int weight(const KeyFrame* kf) const;
  // @}
  // Neighbours by decreasing weight (ties broken by id).
  const std::vector<KeyFrame*>& covisibles() const { return orderedConnected_; }
  // @{
  // The n best neighbours, those with weight at least w, and every neighbour.
  std::vector<KeyFrame*> bestCovisibles(std::size_t n) const;
  std::vector<KeyFrame*> covisiblesWithWeightAtLeast(int w) const;
  std::set<KeyFrame*, ById> connectedSet() const;
  // @}

  // ---- spanning tree and loop edges ----------------------------------------------------
  // Its parent in the spanning tree (null for a map's root).
  KeyFrame* parent() const { return parent_; }
  // @{
  // Spanning-tree children and parent changes; loop edges (a keyframe with one is protected from
  // culling).
  const std::set<KeyFrame*, ById>& children() const { return children_; }
  void changeParent(KeyFrame* parent);
  void addChild(KeyFrame* kf) { children_.insert(kf); }
  void eraseChild(KeyFrame* kf) { children_.erase(kf); }
  bool hasChild(KeyFrame* kf) const { return children_.count(kf) != 0; }
  void addLoopEdge(KeyFrame* kf) { loopEdges_.insert(kf); protected_ = true; }
  const std::set<KeyFrame*, ById>& loopEdges() const { return loopEdges_; }
  // @}

  // ---- life cycle ------------------------------------------------------------------------
  // Whether it was culled.
  bool isBad() const { return bad_; }
  // Keyframes under loop-closing use are protected from culling.
  void setProtected(bool p) { protected_ = p || !loopEdges_.empty(); }
  // Whether culling must spare it.
  bool isProtected() const { return protected_; }
  // Removes the keyframe from the graphs (re-parenting its children by covisibility, as ORB-SLAM
  // does) and detaches its map points. Returns false when it is protected or the root.
  bool setBad();

  // @{
  // ---- the atlas (map mutex held) --------------------------------------------------------
  // The map of the atlas it belongs to (map.hpp); changes when its map is merged into another.
  std::uint32_t mapId() const { return mapId_; }
  void setMapId(std::uint32_t id) { mapId_ = id; }
  // @}
  // @{
  // The first keyframe of its map: never culled. A gauge is a root BA keeps fixed; a root stops
  // being one when its map is merged into another (that map's root holds the gauge).
  bool isMapRoot() const { return mapRoot_; }
  void setMapRoot(bool root) { mapRoot_ = root; gauge_ = root; }
  bool isGauge() const { return gauge_; }
  void setGauge(bool gauge) { gauge_ = gauge && mapRoot_; }
  // @}

  // Relative pose to the parent recorded when the keyframe went bad, so trajectories can still
  // express frames referenced to it.
  const SE3d& poseRelativeToParent() const { return Tcp_; }

  // Per-frame marks of the tracker (map mutex held): the frame, plus one, whose local map last
  // listed this keyframe, and how many of that frame's matches it observes.
  std::uint64_t inLocalMapOf = 0;
  // How many of that frame's matches it observes.
  int sharedMatches = 0;

  // Indices of keypoints within radius r of (u, v) (undistorted pixels).
  std::vector<int> featuresInArea(float u, float v, float r) const;

 private:
  void updateBestCovisibles();
  // Calls f(i) for every slot i that was non-null when its 64-slot word was reached, in order:
  // a slot f empties further on in the same word is still visited, and is then null.
  template <class F>
  void forEachOccupiedSlot(F&& f) const {
    for (std::size_t w = 0; w < occupied_.size(); ++w)
      for (std::uint64_t bits = occupied_[w]; bits != 0; bits &= bits - 1)
        f(w * 64 + static_cast<std::size_t>(std::countr_zero(bits)));
  }
  void markSlot(std::size_t i, bool occupied) {
    const std::uint64_t bit = std::uint64_t{1} << (i % 64);
    std::uint64_t& word = occupied_[i / 64];
    word = occupied ? word | bit : word & ~bit;
  }

  std::shared_ptr<const FrameFeatures> features_;
  mutable std::once_flag bowOnce_;
  mutable BowComputation pendingBow_;  // empty once the vectors are filled
  mutable bow::BowVector bow_;
  mutable bow::FeatureVector featureVector_;
  SE3d Tcw_;
  SE3d Tcp_;
  std::vector<MapPoint*> points_;
  std::vector<std::uint64_t> occupied_;  // bit i: points_[i] is not null
  std::map<KeyFrame*, int, ById> connectedWeights_;
  std::vector<KeyFrame*> orderedConnected_;
  std::vector<int> orderedWeights_;
  bool firstConnection_ = true;
  KeyFrame* parent_ = nullptr;
  std::set<KeyFrame*, ById> children_;
  std::set<KeyFrame*, ById> loopEdges_;
  bool protected_ = false;
  bool bad_ = false;
  std::uint32_t mapId_ = 0;
  bool mapRoot_ = false, gauge_ = false;
};

// The good (non-null, not bad) map points of `keyFrames`, each once, in the order first met
// (keyframe by keyframe, keypoint by keypoint; a bad keyframe has none, setBad detaches them):
// the local point sets of local BA, fusion and loop closing. Deduplicates by sorting pointers rather than through a std::set ordered by id, which
// dereferenced both points on every comparison. Caller holds Map::mutex().
std::vector<MapPoint*> distinctGoodPoints(const std::vector<KeyFrame*>& keyFrames);

}  // namespace orbis
