// orbis/loop/loop_closer.hpp — the loop-closing thread of the paper (§III-D; ORB-SLAM §VII) and
// its full-BA worker: SE(3) loops for metric sensors (stereo, RGB-D), Sim(3) loops for monocular.
//
// Contract: keyframes come from local mapping (insertKeyFrame, the LocalMapper's keyframe sink)
// and are processed in order. Each is added to the keyframe database; loop candidates are those
// of bow::KeyframeDatabase::detectLoopCandidates kept only when their covisibility group stays
// consistent over `consistencyThreshold` consecutive keyframes. For each such candidate: bag-of-
// words matches, then the loop transform by RANSAC over 3-point closed forms (generator seeded
// by options.seed), guided matching both ways and a two-way reprojection refinement; accepted
// with ≥ minPoseInliers, then ≥ minLoopMatches after projecting the candidate's neighbourhood.
// A metric sensor's transform is an SE(3) (relative_pose.hpp); a monocular map's is a Sim(3)
// (sim3_solver.hpp, matching::matchBySim3), whose scale is the drift the loop corrects.
// The correction: local mapping paused, the current keyframe and its covisible keyframes moved
// by the loop transform — as a Sim(3) for monocular, their points mapped through their corrected
// similarity and their poses kept rigid with the scale divided out of t — duplicated points
// merged, covisibility updated, loop edges added, the essential graph optimised (spanning tree,
// loop edges, covisibility ≥ essentialGraphMinWeight; the loop keyframe fixed; in Sim(3) for
// monocular, after which each point follows its corrector's or reference keyframe's similarity),
// then full BA. Metric sensors never take the Sim(3) path (if constexpr on kMetricScale).
// Full BA runs on its own thread in
// threaded mode — aborted and restarted when a new loop closes — and inline in deterministic
// mode; its result is merged under the map lock with local mapping paused: optimised keyframes
// take their new poses, keyframes created meanwhile follow their spanning-tree parent, points
// created meanwhile follow their reference keyframe.
// The atlas (issue 32): candidates in another map of the atlas than the keyframe's are merge
// candidates, kept by the same consistency rule in their own groups and verified by the same
// transform; a merge (loop_merge_impl.hpp) moves the smaller map into the other's frame,
// relabels it, then fuses, optimises the essential graph, runs a welding BA around the seam and
// full BA, as a loop does. Loops and merges stay within one map; full BA and the essential graph
// cover the keyframe's map only.
// Threaded: a worker consumes the queue. Deterministic: nothing runs until runUntilIdle(), which
// does everything (full BA included) on the caller's thread, so results are bit-identical.
// Each step holds Map::mutex(); the essential graph and full BA solve on copies outside it.
// Templated on the sensor (its camera for every projection, its kernel for full BA); local
// mapping is reached through LocalMappingControl. Bodies: loop_closer_impl.hpp (detection) and
// loop_correction_impl.hpp (correction, full BA); built-in sensors compiled in src/loop/.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "orbis/bow/keyframe_database.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/map/local_mapping_control.hpp"
#include "orbis/map/map.hpp"
#include "orbis/map/slam_events.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/util/queue_worker.hpp"
#include "orbis/util/timing.hpp"

namespace orbis {

// Loop closing's thresholds (ORB-SLAM2's unless noted).
struct LoopCloserOptions {
  // Runs on its own thread (false: inline, deterministic mode).
  bool threaded = true;
  // Threaded: loop closing and full BA run at a lower priority than their creator
  // (util/thread_scheduling.hpp).
  bool backgroundPriority = true;
  std::uint32_t seed = 0;               // RANSAC generator
  int consistencyThreshold = 3;         // consecutive keyframes a candidate group must persist
  int keyFramesAfterLoop = 10;          // no detection this soon after the last loop (ORB-SLAM)
  int minBowMatches = 20;               // candidate needs this many bag-of-words matches
  int minPoseInliers = 20;              // after guided matching and refinement
  int minLoopMatches = 40;              // after projecting the loop neighbourhood
  int essentialGraphMinWeight = 100;    // covisibility edges kept in the essential graph
  // @{
  // Whether a full BA runs after a loop correction, and its iterations.
  bool fullBundleAdjustment = true;
  int fullBundleAdjustmentIterations = 10;
  // @}
  // @{
  // Merging maps of the atlas: on, and the active map's keyframes a merge needs.
  bool mergeMaps = true;
  int mergeMinKeyFrames = 5;
  // @}
  // Receives "loop closed: ..." lines; null prints them to stderr.
  std::function<void(const std::string&)> log;
};


// Loop closing (§III-D, §V): detection by bag of words, a verified Sim(3) (SE(3) for metric
// sensors), loop fusion, essential-graph optimisation, then a full BA on a worker.
template <SensorConfiguration Sensor>
class LoopCloser {
 public:
  // The sensor's camera model.
  using Camera = typename Sensor::Camera;
  // The loop's correction of a pose: rigid for metric sensors, a similarity for monocular.
  using Correction = std::conditional_t<Sensor::kMetricScale, SE3d, Sim3d>;

  // `camera` must outlive the loop closer (the SLAM system owns it).
  LoopCloser(const Camera& camera, Map& map, LocalMappingControl* mapper, bow::KeyframeDatabase& database,
             LoopCloserOptions options, StageTimer* timer = nullptr);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  // Local mapping's keyframe sink (any thread).
  void insertKeyFrame(KeyFrame* kf);
  // Deterministic mode: process every queued keyframe now, on this thread.
  void runUntilIdle();
  // Block until the queue is empty, the worker idle and no full BA is running.
  void waitUntilIdle();
  // Finishes queued work and joins the threads.
  void shutdown();

  // @{
  // The loops closed so far, in order.
  std::vector<LoopClosureEvent> closures() const;
  std::vector<MapMergeEvent> merges() const;
  // @}

 private:
  struct ConsistentGroup {
    std::set<KeyFrameId> members;
    int consistency = 0;
  };
  struct LoopCandidate {
    KeyFrame* loopKeyFrame = nullptr;
    SE3d correctedTcw;                  // the current keyframe's pose seen from the loop side
    Correction correctedScw;            // the same with the loop side's scale (Sim(3) for monocular)
    std::vector<MapPoint*> matches;     // per keypoint of the current keyframe: loop-side point
    std::vector<MapPoint*> loopPoints;  // points of the loop keyframe's neighbourhood
    int matched = 0;
  };

  bool processOne();
  // Holding the map mutex:
  void dropBadKeyFrames();
  // Loop candidates (same map), and in mergeCandidates those of other maps of the atlas.
  std::vector<KeyFrame*> detectConsistentCandidates(KeyFrame* kf, std::vector<KeyFrame*>& mergeCandidates);
  // ORB-SLAM's consistency check of candidates against the previous keyframes' groups.
  std::vector<KeyFrame*> keepConsistent(const std::vector<KeyFrame*>& candidates, std::vector<ConsistentGroup>& groups);
  bool computeRelativePose(KeyFrame* kf, const std::vector<KeyFrame*>& candidates, LoopCandidate& out);
  // One candidate's transform from its bag-of-words matches (ORB-SLAM's ComputeSim3): RANSAC,
  // guided matching both ways through its result, two-way refinement; SE(3) or Sim(3) by the
  // sensor. Fills out.loopKeyFrame, the corrected pose and the inlier matches.
  bool loopTransform(KeyFrame* kf, KeyFrame* candidate, const std::vector<MapPoint*>& matches, LoopCandidate& out);
  // Takes the map mutex itself (pauses local mapping first):
  void correctLoop(KeyFrame* kf, LoopCandidate& loop);
  // The map-merge counterpart (loop_merge_impl.hpp).
  void mergeMaps(KeyFrame* kf, LoopCandidate& loop);
  // Holding the map mutex: moves map `moved` into the frame of `kept` (x_kept = S·x_moved).
  void moveMap(std::uint32_t moved, const Correction& S);

  using PoseMap = std::map<KeyFrame*, SE3d, ById>;
  using LinkMap = std::map<KeyFrame*, std::set<KeyFrame*, ById>, ById>;
  using CorrectionMap = std::map<KeyFrame*, Correction, ById>;
  using PointCorrectors = std::map<MapPoint*, KeyFrame*, ById>;
  struct Fusion {
    PoseMap nonCorrected;
    CorrectionMap corrected;
    LinkMap loopLinks;
    PointCorrectors correctedBy;
  };
  // The loop's correction of the current keyframe's neighbourhood, fusion and links (the part
  // correctLoop and mergeMaps share); takes the lock. Returns the points fused.
  int fuseAcrossLoop(KeyFrame* kf, LoopCandidate& loop, Fusion& fusion);
  void optimiseEssentialGraph(KeyFrame* kf, KeyFrame* loopKf, const PoseMap& nonCorrected, const CorrectionMap& corrected,
                              const LinkMap& loopLinks, const PointCorrectors& correctedBy);
  void startFullBundleAdjustment(std::uint32_t mapId);
  void runFullBundleAdjustment();
  void stopFullBundleAdjustment();
  void pauseMapping();
  void resumeMapping();
  void report(const std::string& line) const;

  const Camera& camera_;
  Map& map_;
  LocalMappingControl* mapper_;
  bow::KeyframeDatabase& database_;
  LoopCloserOptions options_;
  StageTimer* timer_;
  std::mt19937 rng_;


  std::vector<KeyFrame*> indexed_;  // keyframes in the database (loop thread only)
  std::vector<ConsistentGroup> consistentGroups_;
  std::vector<ConsistentGroup> mergeGroups_;
  KeyFrameId lastLoopKeyFrame_ = 0;
  bool anyLoop_ = false;

  mutable std::mutex eventsMutex_;
  std::vector<LoopClosureEvent> events_;
  std::vector<MapMergeEvent> merges_;

  std::thread fullBaThread_;
  std::atomic<bool> abortFullBa_{false};
  std::atomic<bool> fullBaRunning_{false};
  std::uint32_t fullBaMap_ = 0;  // the map the running full BA optimises

  QueueWorker<KeyFrame*> worker_;  // last: its thread stops before the state it serves goes
};

}  // namespace orbis

#include "orbis/loop/loop_closer_impl.hpp"
#include "orbis/loop/loop_correction_impl.hpp"
#include "orbis/loop/loop_merge_impl.hpp"

namespace orbis {
extern template class LoopCloser<Stereo>;
extern template class LoopCloser<Rgbd>;
extern template class LoopCloser<Monocular>;
extern template class LoopCloser<MonocularFisheye>;
}  // namespace orbis
