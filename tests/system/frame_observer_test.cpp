// The observer seam a live viewer uses (viewer/slam_observer.hpp): a FrameObserver sees every
// frame with its keypoint states and its input image (shared), mapSnapshot() copies the map, and
// observing changes nothing.
#include <gtest/gtest.h>

#include <algorithm>

#include "orbis/synth/sequence.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"

namespace {

using namespace orbis;

struct ObservedRun {
  Trajectory trajectory;
  SlamStats stats;
  std::vector<FrameSnapshot> frames;
  std::vector<const uchar*> inputPixels;  // where each input image's pixels were
  MapSnapshot map;
};

ObservedRun runRendered(bool observe) {
  synth::SynthOptions options;
  options.frames = 60;
  options.width = 320;
  options.height = 240;
  options.fx = 250;
  options.seed = 5;
  options.threads = 2;
  synth::SyntheticSequence seq(options);
  SlamOptions slamOptions;
  slamOptions.deterministic = true;
  slamOptions.fps = options.fps;
  OrbParams orb;
  orb.features = 800;
  Slam<Rgbd> slam(test::syntheticCamera<Rgbd>(seq, options.baseline), orb, test::sharedVocabulary(), slamOptions);
  ObservedRun run;
  if (observe) slam.setFrameObserver([&run](FrameSnapshot&& frame) { run.frames.push_back(std::move(frame)); });
  for (int i = 0; i < seq.size(); ++i) {
    const auto input = test::syntheticInput<Rgbd>(seq.render(i, false, true), seq.timestamp(i));
    run.inputPixels.push_back(input.image.data);
    slam.track(input);
  }
  slam.shutdown();
  run.trajectory = slam.trajectory();
  run.stats = slam.stats();
  run.map = slam.mapSnapshot();
  return run;
}

TEST(FrameObserver, SeesEveryFrameWithKeypointStatesAndChangesNothing) {
  const ObservedRun plain = runRendered(false);
  const ObservedRun observed = runRendered(true);
  ASSERT_EQ(plain.trajectory.size(), observed.trajectory.size());
  for (std::size_t i = 0; i < plain.trajectory.size(); ++i)
    EXPECT_EQ(plain.trajectory[i].pose.matrix(), observed.trajectory[i].pose.matrix()) << "frame " << i;

  ASSERT_EQ(observed.frames.size(), observed.stats.frames);
  for (std::size_t i = 0; i < observed.frames.size(); ++i) {
    const FrameSnapshot& f = observed.frames[i];
    EXPECT_EQ(f.index, i);
    ASSERT_TRUE(f.features);
    ASSERT_EQ(f.keypointStates.size(), f.features->size());
    const auto count = [&](KeypointState s) { return std::count(f.keypointStates.begin(), f.keypointStates.end(), s); };
    if (i == 0) EXPECT_GT(count(KeypointState::New), 100) << "the first frame seeds the map";
    else if (f.state == TrackingState::Ok) EXPECT_GT(count(KeypointState::Matched), 20) << "frame " << i;
    if (f.newKeyFrame && i > 0) EXPECT_GT(count(KeypointState::New), 0) << "frame " << i;
    if (f.state == TrackingState::Ok) EXPECT_FALSE(f.localMapPoints.empty());
    // The input image itself, shared, not copied on the tracking thread.
    EXPECT_EQ(f.image.data, observed.inputPixels[i]) << "frame " << i;
    EXPECT_EQ(f.imageWidth, 320);
    EXPECT_EQ(f.imageHeight, 240);
  }
}

TEST(FrameObserver, MapSnapshotCopiesTheMap) {
  const ObservedRun run = runRendered(false);
  EXPECT_EQ(run.map.keyFrames.size(), run.stats.keyFrames);
  EXPECT_EQ(run.map.points.size(), run.stats.mapPoints);
  EXPECT_EQ(run.map.trajectory.size(), run.stats.tracked);
  EXPECT_EQ(run.map.frames, run.stats.frames);
  ASSERT_FALSE(run.map.keyFrames.empty());
  EXPECT_EQ(run.map.keyFrames.front().parent, -1);
  for (std::size_t i = 1; i < run.map.keyFrames.size(); ++i) EXPECT_GE(run.map.keyFrames[i].parent, 0);
}

}  // namespace
