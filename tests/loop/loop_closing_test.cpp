// End-to-end tests of loop closing: synthetic sequences that return to their start (always run)
// and the real benchmark slices, where no loop exists (skipped when ../shared/datasets is absent).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "orbis/eval/metrics.hpp"
#include "orbis/loop/loop_closer.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/util/error.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"
#include "test_data.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;

using test::loopSequence;

struct LoopRun {
  Trajectory estimate, keyFrames, groundTruth;
  SlamStats stats;
  std::vector<LoopClosureEvent> closures;
  std::uint64_t firstLoopKeyFrameFrame = 0;  // frame the first closure's loop keyframe came from
};

template <class Sensor>
LoopRun runLoop(const synth::SynthOptions& options, bool loopClosing, bool deterministic) {
  synth::SyntheticSequence seq(options);
  const auto camera = test::syntheticCamera<Sensor>(seq, options.baseline);
  OrbParams orb;
  orb.features = 800;
  SlamOptions slamOptions;
  slamOptions.deterministic = deterministic;
  slamOptions.loopClosing = loopClosing;
  slamOptions.fps = options.fps;
  slamOptions.seed = 11;
  Slam<Sensor> slam(camera, orb, test::sharedVocabulary(), slamOptions);
  LoopRun run;
  // One loop and a quarter: the camera comes back to its start and keeps going over known ground,
  // as loop detection needs a few consecutive keyframes there (the renderer's path is periodic).
  const int frames = seq.size() + seq.size() / 4;
  for (int i = 0; i < frames; ++i) {
    synth::SynthFrame f = seq.render(i, Sensor::kKind == SensorKind::Stereo, Sensor::kDepthFromSensor);
    run.groundTruth.push_back({seq.timestamp(i), f.pose});
    slam.track(test::syntheticInput<Sensor>(f, seq.timestamp(i)));
  }
  slam.shutdown();
  run.estimate = slam.trajectory();
  run.keyFrames = slam.keyFrameTrajectory();
  run.stats = slam.stats();
  if (const auto* closer = slam.core().loopCloser()) run.closures = closer->closures();
  if (!run.closures.empty()) {
    std::lock_guard lock(slam.core().map().mutex());
    run.firstLoopKeyFrameFrame = slam.core().map().keyFrame(run.closures.front().loop)->frameIndex;
  }
  return run;
}

double ateRmse(const LoopRun& run, const Trajectory& estimate) {
  return eval::computeAte(run.groundTruth, estimate, {eval::Alignment::SE3, 0.001}).stats.rmse;
}
double ateRmse(const LoopRun& run) { return ateRmse(run, run.estimate); }

// Translation error of the estimated motion from frame `from` to the last frame: with `from`
// at the start of the loop and the last frame past its end, the drift the loop accumulated.
double loopDrift(const LoopRun& run, std::uint64_t from) {
  const auto poseAt = [](const Trajectory& trajectory, double t) {
    const auto it = std::find_if(trajectory.begin(), trajectory.end(), [t](const StampedPose& p) { return p.t == t; });
    EXPECT_NE(it, trajectory.end());
    return it == trajectory.end() ? SE3d() : it->pose;
  };
  const StampedPose& start = run.groundTruth.at(from);
  const StampedPose& end = run.groundTruth.back();
  const SE3d truth = start.pose.inverse() * end.pose;
  const SE3d estimate = poseAt(run.estimate, start.t).inverse() * poseAt(run.estimate, end.t);
  return (truth.inverse() * estimate).translation().norm();
}

bool identical(const Trajectory& a, const Trajectory& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].t != b[i].t || a[i].pose.matrix() != b[i].pose.matrix()) return false;
  return true;
}

template <class Sensor>
void checkLoopRemovesDrift(const char* name, std::uint64_t seed) {
  const auto options = loopSequence(seed);
  const LoopRun open = runLoop<Sensor>(options, false, true);
  const LoopRun closed = runLoop<Sensor>(options, true, true);
  const double ateOpen = ateRmse(open), ateClosed = ateRmse(closed);
  const double mapOpen = ateRmse(open, open.keyFrames), mapClosed = ateRmse(closed, closed.keyFrames);
  std::cout << "[loop] synthetic " << name << ": ATE without loop closing " << ateOpen * 1000 << " mm, with "
            << ateClosed * 1000 << " mm (ratio " << ateClosed / ateOpen << "); keyframes " << mapOpen * 1000 << " mm, "
            << mapClosed * 1000 << " mm (ratio " << mapClosed / mapOpen << "); " << closed.closures.size()
            << " closure(s), " << closed.stats.keyFrames << " keyframes\n";
  const double driftOpen = loopDrift(open, closed.firstLoopKeyFrameFrame);
  const double driftClosed = loopDrift(closed, closed.firstLoopKeyFrameFrame);
  std::cout << "[loop] synthetic " << name << ": drift from frame " << closed.firstLoopKeyFrameFrame
            << " to the last, without loop closing " << driftOpen * 1000 << " mm, with " << driftClosed * 1000
            << " mm (ratio " << driftClosed / driftOpen << ")\n";
  for (const LoopClosureEvent& e : closed.closures)
    std::cout << "[loop]   keyframe " << e.current << " <-> keyframe " << e.loop << " at frame " << e.frameIndex << ", "
              << e.inliers << " inliers\n";
  EXPECT_EQ(closed.stats.lost, 0u);
  EXPECT_EQ(open.stats.loopClosures, 0u);
  ASSERT_GE(closed.closures.size(), 1u);
  // Closed once the camera came back: late in the sequence, to a keyframe from its beginning.
  const auto frames = static_cast<std::uint64_t>(options.frames);
  EXPECT_GE(closed.closures.front().frameIndex, frames * 3 / 4);
  EXPECT_LE(closed.firstLoopKeyFrameFrame, frames / 4);
  // Loop closing removes the drift the loop accumulated: the motion from the loop's start to
  // the last frame loses at least two thirds of its error (measured: RGB-D 46.6 -> 4.7 mm,
  // stereo 140.3 -> 5.9 mm). The aligned ATEs improve too, but by a share that depends on how
  // much drift the open run happened to gather against a floor loop closing cannot lower:
  // every frame's own tracking error (on this 320x240 sequence about 20 mm, up to 10 cm on
  // frames far from their keyframe, where a wall-dominated view leaves rotation and translation
  // barely separable). Measured keyframes / whole trajectory: RGB-D 0.45 / 0.52, stereo
  // 0.15 / 0.28; a change to the quadtree's tie-break alone once made the RGB-D pair 0.21 /
  // 0.26. So the keyframes are held to three quarters and the whole trajectory to improving.
  EXPECT_LE(driftClosed, driftOpen / 3);
  EXPECT_LE(mapClosed, 0.75 * mapOpen);
  EXPECT_LT(ateClosed, ateOpen);
}

TEST(LoopClosing, SyntheticRgbdLoopIsClosedAndRemovesDrift) { checkLoopRemovesDrift<Rgbd>("RGB-D", 21); }
TEST(LoopClosing, SyntheticStereoLoopIsClosedAndRemovesDrift) { checkLoopRemovesDrift<Stereo>("stereo", 22); }

// The estimate's scale against the ground truth over frames [from, to) of the trajectory: the
// Sim(3) alignment's scale on that stretch alone.
double localScale(const LoopRun& run, const Trajectory& estimate, std::size_t from, std::size_t to) {
  const Trajectory part(estimate.begin() + static_cast<long>(from), estimate.begin() + static_cast<long>(to));
  return eval::computeAte(run.groundTruth, part, {eval::Alignment::Sim3, 0.001}).alignment.scale();
}

// A monocular map drifts in scale as well as in pose: the loop is closed as a Sim(3), whose scale
// is that drift, and the correction removes it (scale at the loop's end against its start).
TEST(LoopClosing, SyntheticMonocularLoopIsClosedAsSim3AndRemovesDrift) {
  const auto options = loopSequence(43);
  const LoopRun open = runLoop<Monocular>(options, false, true);
  const LoopRun closed = runLoop<Monocular>(options, true, true);
  const auto ate = [&](const LoopRun& run) {
    return eval::computeAte(run.groundTruth, run.estimate, {eval::Alignment::Sim3, 0.001}).stats.rmse;
  };
  const double ateOpen = ate(open), ateClosed = ate(closed);
  // Scale drift: the last 60 frames (back over the loop's start) against the first 60 tracked.
  const auto scaleDrift = [&](const LoopRun& run) {
    const std::size_t n = run.estimate.size();
    return localScale(run, run.estimate, n - 60, n) / localScale(run, run.estimate, 0, 60);
  };
  const double driftOpen = scaleDrift(open), driftClosed = scaleDrift(closed);
  std::cout << "[loop] synthetic monocular: ATE (Sim3) without loop closing " << ateOpen * 1000 << " mm, with "
            << ateClosed * 1000 << " mm (ratio " << ateClosed / ateOpen << "); scale end/start " << driftOpen
            << " without, " << driftClosed << " with; " << closed.closures.size() << " closure(s), "
            << closed.stats.keyFrames << " keyframes\n";
  for (const LoopClosureEvent& e : closed.closures)
    std::cout << "[loop]   keyframe " << e.current << " <-> keyframe " << e.loop << " at frame " << e.frameIndex << ", "
              << e.inliers << " inliers, Sim(3) scale " << e.scale << "\n";
  EXPECT_EQ(closed.stats.lost, 0u);
  EXPECT_EQ(open.stats.loopClosures, 0u);
  ASSERT_GE(closed.closures.size(), 1u);
  const auto frames = static_cast<std::uint64_t>(options.frames);
  EXPECT_GE(closed.closures.front().frameIndex, frames * 3 / 4);
  EXPECT_LE(closed.firstLoopKeyFrameFrame, frames / 4);
  EXPECT_NE(closed.closures.front().scale, 1.0);  // a similarity, not a rigid motion
  // Measured (seed 43): ATE 77.0 -> 17.3 mm (ratio 0.22), scale end/start 1.091 -> 0.997, Sim(3) scale 0.924.
  EXPECT_LE(ateClosed, ateOpen / 3);
  EXPECT_LT(std::abs(std::log(driftClosed)), 0.5 * std::abs(std::log(driftOpen)));
}

TEST(LoopClosing, DeterministicModeIsBitIdenticalWithLoopClosing) {
  const auto options = loopSequence(21);
  const LoopRun a = runLoop<Rgbd>(options, true, true);
  const LoopRun b = runLoop<Rgbd>(options, true, true);
  ASSERT_GE(a.closures.size(), 1u);  // the comparison must cover a closure and its full BA
  EXPECT_TRUE(identical(a.estimate, b.estimate));
}

// Threaded mode (the ThreadSanitizer build runs this one): loop closing and full BA on their own
// threads while tracking continues.
TEST(LoopClosing, ThreadedRunClosesTheLoop) {
  const auto options = loopSequence(21);
  const LoopRun run = runLoop<Rgbd>(options, true, false);
  const double ate = ateRmse(run);
  std::cout << "[loop] threaded RGB-D: ATE " << ate * 1000 << " mm, " << run.closures.size() << " closure(s)\n";
  EXPECT_GE(run.closures.size(), 1u);
  EXPECT_EQ(run.stats.tracked, run.stats.frames);
}

RunReport runReal(DatasetReader& dataset, const fs::path& out, bool loopClosing) {
  RunOptions options;
  options.vocabulary = defaultVocabularyPath();
  options.outDir = out;
  options.deterministic = true;
  options.progress = false;
  options.loopClosing = loopClosing;
  return runDataset(dataset, options);
}

void checkNoFalseLoop(DatasetKind kind, const fs::path& root, const char* name) {
  auto dataset = openDataset(kind, root);
  const RunReport closed = runReal(*dataset, fs::temp_directory_path() / "orbis_loop_real_on", true);
  auto again = openDataset(kind, root);
  const RunReport open = runReal(*again, fs::temp_directory_path() / "orbis_loop_real_off", false);
  ASSERT_TRUE(closed.ateRmse && open.ateRmse);
  std::cout << "[loop] " << name << ": " << closed.stats.loopClosures << " closure(s); ATE with loop closing "
            << *closed.ateRmse * 1000 << " mm, without " << *open.ateRmse * 1000 << " mm\n";
  EXPECT_EQ(closed.stats.loopClosures, 0u);
  EXPECT_LE(*closed.ateRmse, *open.ateRmse * 1.0000001);
}

TEST(LoopClosing, NoFalseLoopOnTumTeddy) {
  ORBIS_REQUIRE_DATASET(root, "tum_fr3_teddy_200");
  checkNoFalseLoop(DatasetKind::TumRgbd, root, "TUM teddy RGB-D");
}

TEST(LoopClosing, NoFalseLoopOnEuroc) {
  ORBIS_REQUIRE_DATASET(root, "euroc_V1_01_easy_95");
  checkNoFalseLoop(DatasetKind::Euroc, root, "EuRoC V1_01 stereo");
}

}  // namespace
