// Local mapping's hand-over with tracking (mapping/local_mapper.hpp), on keyframes without
// keypoints, so only the queue, the waits and the bag-of-words hand-over are exercised:
//  - a live camera's tracking waits only until the last keyframe's new points exist
//    (waitUntilTriangulatedFor), not until fusion, local BA and the keyframe sink are done;
//  - stereo/RGB-D tracking fed faster than a camera waits until the queue has room
//    (waitUntilQueuedBelowFor), and the wait ends as soon as mapping takes a keyframe;
//  - a keyframe whose bag of words tracking left for later gets it on the mapping thread.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "orbis/mapping/local_mapper.hpp"

namespace orbis {
namespace {

using namespace std::chrono_literals;

PinholeCamera<double> smallCamera() {
  PinholeCamera<double> camera;
  camera.fx = camera.fy = 250;
  camera.cx = 160;
  camera.cy = 120;
  camera.width = 320;
  camera.height = 240;
  return camera;
}

KeyFrame* emptyKeyFrame(Map& map, std::uint64_t frame, BowComputation bow = nullptr) {
  std::lock_guard lock(map.mutex());
  auto features = std::make_shared<const FrameFeatures>();
  MapIntrinsics bounds;
  bounds.maxX = 320;
  bounds.maxY = 240;
  if (bow) return map.createKeyFrame(frame, static_cast<double>(frame), SE3d(), features, bounds, std::move(bow));
  return map.createKeyFrame(frame, static_cast<double>(frame), SE3d(), features, bounds, {}, {});
}

// Holds the mapping thread in the keyframe sink (after triangulation, fusion and local BA)
// until released.
struct SinkGate {
  std::mutex mutex;
  std::condition_variable cv;
  bool open = false;
  std::atomic<int> entered{0};

  void pass() {
    ++entered;
    std::unique_lock lock(mutex);
    cv.wait(lock, [&] { return open; });
  }
  void release() {
    {
      std::lock_guard lock(mutex);
      open = true;
    }
    cv.notify_all();
  }
  void waitUntilEntered(int n) {
    const auto deadline = std::chrono::steady_clock::now() + 10s;
    while (entered.load() < n && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(1ms);
  }
};

TEST(LocalMapper, LiveWaitEndsWhenTheKeyFrameIsTriangulatedNotWhenMappingIsIdle) {
  const PinholeCamera<double> camera = smallCamera();
  Map map;
  LocalMapper<Monocular> mapper(camera, map, LocalMapperOptions{});
  SinkGate gate;
  mapper.setKeyFrameSink([&](KeyFrame*) { gate.pass(); });

  EXPECT_TRUE(mapper.waitUntilTriangulatedFor(0ms)) << "nothing queued: nothing to wait for";

  mapper.insertKeyFrame(emptyKeyFrame(map, 0));
  // The first keyframe's points exist while the mapping thread is still busy with it (held in
  // the sink): the live wait returns, the wait for an idle mapper does not.
  EXPECT_TRUE(mapper.waitUntilTriangulatedFor(10s));
  gate.waitUntilEntered(1);
  ASSERT_EQ(gate.entered.load(), 1);
  EXPECT_FALSE(mapper.waitUntilIdleFor(50ms));

  // A second keyframe queued behind the held one is not triangulated yet: the wait times out.
  mapper.insertKeyFrame(emptyKeyFrame(map, 1));
  EXPECT_FALSE(mapper.waitUntilTriangulatedFor(50ms));

  gate.release();
  EXPECT_TRUE(mapper.waitUntilTriangulatedFor(10s));
  EXPECT_TRUE(mapper.waitUntilIdleFor(10s));
  EXPECT_EQ(gate.entered.load(), 2);
  mapper.shutdown();
}

TEST(LocalMapper, QueueWaitEndsWhenMappingTakesAKeyFrame) {
  const PinholeCamera<double> camera = smallCamera();
  Map map;
  LocalMapper<Monocular> mapper(camera, map, LocalMapperOptions{});  // the queue is the same for every sensor
  SinkGate gate;
  mapper.setKeyFrameSink([&](KeyFrame*) { gate.pass(); });

  // One keyframe held in the sink, three queued behind it: no room.
  mapper.insertKeyFrame(emptyKeyFrame(map, 0));
  gate.waitUntilEntered(1);
  ASSERT_EQ(gate.entered.load(), 1);
  EXPECT_TRUE(mapper.waitUntilQueuedBelowFor(1, 0ms)) << "the held keyframe is no longer queued";
  for (std::uint64_t frame = 1; frame <= 3; ++frame) mapper.insertKeyFrame(emptyKeyFrame(map, frame));
  ASSERT_EQ(mapper.queuedKeyFrames(), 3u);
  EXPECT_TRUE(mapper.waitUntilQueuedBelowFor(4, 0ms));
  EXPECT_FALSE(mapper.waitUntilQueuedBelowFor(3, 50ms));

  // Released, mapping takes the next keyframe off the queue; the wait ends with room for one.
  std::thread releaser([&] {
    std::this_thread::sleep_for(20ms);
    gate.release();
  });
  // At the budget the wait reports its condition anyway, so only the time shows a missed wake.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(mapper.waitUntilQueuedBelowFor(3, 30s));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 15s) << "woken by the budget, not by mapping";
  EXPECT_LT(mapper.queuedKeyFrames(), 3u);
  releaser.join();
  EXPECT_TRUE(mapper.waitUntilIdleFor(10s));
  EXPECT_EQ(gate.entered.load(), 4);
  mapper.shutdown();
}

TEST(LocalMapper, ComputesALeftOverBagOfWordsOnItsOwnThread) {
  const PinholeCamera<double> camera = smallCamera();
  Map map;
  LocalMapper<Monocular> mapper(camera, map, LocalMapperOptions{});
  std::atomic<int> calls{0};
  std::thread::id computedOn;
  KeyFrame* kf = emptyKeyFrame(map, 0, [&](const FrameFeatures&, bow::BowVector& words, bow::FeatureVector&) {
    computedOn = std::this_thread::get_id();
    ++calls;
    words = bow::BowVector::fromUnsorted({{7, 0.5}}, false);
  });
  EXPECT_EQ(calls.load(), 0) << "made without computing its words";
  mapper.insertKeyFrame(kf);
  mapper.waitUntilIdle();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_NE(computedOn, std::this_thread::get_id());
  ASSERT_EQ(kf->bowVector().size(), 1u);
  EXPECT_EQ(kf->bowVector()[0].word, 7u);
  EXPECT_EQ(calls.load(), 1) << "computed once";
  mapper.shutdown();
}

}  // namespace
}  // namespace orbis
