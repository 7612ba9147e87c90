// orbis/mapping/local_mapper.hpp — the local-mapping thread of the paper (§III; ORB-SLAM §VI).
//
// Contract: keyframes handed over by tracking are processed in order: insertion (observations,
// covisibility), culling of recent points that are rarely found, triangulation of new points
// with the covisible keyframes, fusion of duplicates in the neighbourhood, local BA, and culling
// of keyframes whose points 90% of which are seen by three others at the same or finer scale.
// Threaded: a worker thread consumes the queue (local BA can be interrupted by tracking).
// Deterministic: nothing runs until the owner calls runUntilIdle(), which processes the whole
// queue on the caller's thread. Each step holds Map::mutex(); local BA solves on a copy
// outside it. Processed keyframes are passed to the keyframe sink (loop closing). Templated on
// the sensor (its camera for every projection, its kernel for local BA, its trait for the
// stereo-only rules); tracking and loop closing reach it through LocalMappingControl. Bodies:
// local_mapper_impl.hpp; the built-in sensors are compiled in src/mapping/local_mapper.cpp.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <mutex>
#include <thread>

#include "orbis/map/local_mapping_control.hpp"
#include "orbis/map/map.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/util/queue_worker.hpp"
#include "orbis/util/timing.hpp"

namespace orbis {

// Local mapping's settings.
struct LocalMapperOptions {
  // Runs on its own thread (false: inline, deterministic mode).
  bool threaded = true;
  // Threaded: the thread runs at a lower priority than its creator (util/thread_scheduling.hpp).
  bool backgroundPriority = true;
  int triangulationNeighbours = 10;  // covisible keyframes searched for new points (stereo)
  double redundancyRatio = 0.9;      // keyframe culling: share of points seen elsewhere
  // Whether redundant keyframes are culled.
  bool cullKeyFrames = true;
};

// Local mapping (§III-C/§VI): keyframe insertion, recent map point culling, new points by
// triangulation (and from depth), fusion, local BA and keyframe culling.
template <SensorConfiguration Sensor>
class LocalMapper final : public LocalMappingControl {
 public:
  // The sensor's camera model.
  using Camera = typename Sensor::Camera;

  // `camera` must outlive the mapper (the SLAM system owns it).
  LocalMapper(const Camera& camera, Map& map, LocalMapperOptions options, StageTimer* timer = nullptr);
  ~LocalMapper() override;
  LocalMapper(const LocalMapper&) = delete;
  LocalMapper& operator=(const LocalMapper&) = delete;

  // Called by tracking (with the map mutex held): queue a new keyframe.
  void insertKeyFrame(KeyFrame* kf) override;
  std::size_t queuedKeyFrames() const override;
  bool acceptsKeyFrames() const override { return acceptKeyFrames_.load(); }
  void interruptBundleAdjustment() override { abortBA_ = true; }

  // Loop closing pauses local mapping while it corrects the map.
  void requestStop() override;
  bool isStopped() const override;
  bool isStoppedOrStopping() const override;
  // While set, a stop request is not honoured (tracking is creating a keyframe). Returns false
  // when the mapper is already stopped.
  bool setNotStop(bool flag) override;
  void release() override;

  // Deterministic mode: process every queued keyframe now, on this thread.
  void runUntilIdle();
  // Threaded mode: block until the queue is empty and the worker is idle.
  void waitUntilIdle();
  // Threaded mode: the same for at most `budget`; true when idle.
  bool waitUntilIdleFor(std::chrono::steady_clock::duration budget);
  // Threaded mode: block for at most `budget` until every keyframe queued so far has its new map
  // points (triangulation done; fusion and local BA may still run); true when they have.
  bool waitUntilTriangulatedFor(std::chrono::steady_clock::duration budget);
  // Threaded mode: block for at most `budget` until fewer than `count` keyframes are queued; true
  // when they are.
  bool waitUntilQueuedBelowFor(std::size_t count, std::chrono::steady_clock::duration budget);
  // Finishes queued work and joins the thread.
  void shutdown();

  // Where each processed keyframe goes next (loop closing).
  void setKeyFrameSink(std::function<void(KeyFrame*)> sink) { sink_ = std::move(sink); }
  // Called for each keyframe culling retires, with the map mutex held (keyframe database upkeep).
  void setCulledKeyFrameSink(std::function<void(KeyFrame*)> sink) { culledSink_ = std::move(sink); }

 private:
  void serveQueue();  // the worker's turn (threaded mode)
  bool processOne();
  void processNewKeyFrame(KeyFrame* kf);
  void cullRecentPoints(KeyFrame* kf);
  void createNewMapPoints(KeyFrame* kf);
  void fuseWithNeighbours(KeyFrame* kf);
  void cullKeyFrames(KeyFrame* kf);
  bool stopIfRequested();

  const Camera& camera_;
  Map& map_;
  LocalMapperOptions options_;
  StageTimer* timer_;
  // Diagnosis (`orbis run --stats`): counters of the keyframe being processed, logged with it.
  std::vector<std::pair<std::string, double>> diagnostics_;
  void note(const char* name, double value) {
    if (timer_ && timer_->eventsEnabled()) diagnostics_.emplace_back(name, value);
  }
  std::function<void(KeyFrame*)> sink_, culledSink_;

  std::list<MapPoint*> recentPoints_;
  // Keyframes queued and keyframes whose new points are made (waitUntilTriangulatedFor).
  std::mutex triangulatedMutex_;
  std::condition_variable triangulatedCv_;
  std::uint64_t queuedTotal_ = 0, triangulatedTotal_ = 0;
  std::atomic<bool> acceptKeyFrames_{true};
  std::atomic<bool> abortBA_{false};

  mutable std::mutex stopMutex_;
  bool stopRequested_ = false, stopped_ = false, notStop_ = false;

  QueueWorker<KeyFrame*> worker_;  // last: its thread stops before the state it serves goes
};

}  // namespace orbis

#include "orbis/mapping/local_mapper_impl.hpp"

namespace orbis {
extern template class LocalMapper<Stereo>;
extern template class LocalMapper<Rgbd>;
extern template class LocalMapper<Monocular>;
extern template class LocalMapper<MonocularFisheye>;
}  // namespace orbis
