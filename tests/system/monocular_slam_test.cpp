// Monocular SLAM end to end (issue 17), beside the stereo and RGB-D tests of
// slam_pipeline_test.cpp and relocalisation_test.cpp:
//  - a rendered loop with image noise: the map initialises within the first 30 frames, every
//    frame after that is tracked, and the Sim(3)-aligned ATE stays under 1% of the path;
//  - the same loop at 320x240 with stronger noise initialises within 30 frames too;
//  - threaded with no time to spare in the frame period (a slow machine): the scale holds;
//  - deterministic mode twice on the same frames: bit-identical trajectories;
//  - a saved monocular map loads into a fresh system that localises in it without new keyframes;
//  - a static camera, a pure rotation and a textureless view never start a map, and the
//    system says why (Tracker::initialisationWaits).
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include <unistd.h>

#include "orbis/eval/metrics.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;
using test::identical;
using test::pathLength;

// 640x480: at 320x240 the finest pyramid level holds too few corners for the 100 window matches
// the two-view initialiser needs (measured: 85-150 matches, the reference dropped every few frames).
synth::SynthOptions monoOptions(int frames, std::uint64_t seed) {
  synth::SynthOptions o;
  o.frames = frames;
  o.noiseSigma = 2.0;
  o.seed = seed;
  o.threads = 2;
  return o;
}

std::vector<synth::SynthFrame> render(const synth::SynthOptions& options) {
  synth::SyntheticSequence seq(options);
  std::vector<synth::SynthFrame> out;
  for (int i = 0; i < seq.size(); ++i) out.push_back(seq.render(i, false, false));
  return out;
}

// The loop's first 90 frames, rendered once per process: every test below replays them.
const synth::SynthOptions& loopOptions() {
  static const synth::SynthOptions options = monoOptions(300, 3);
  return options;
}
constexpr int kLoopFrames = 90;
const std::vector<synth::SynthFrame>& loopFrames() {
  static const std::vector<synth::SynthFrame> cache = [] {
    synth::SynthOptions o = loopOptions();
    synth::SyntheticSequence seq(o);
    std::vector<synth::SynthFrame> out;
    for (int i = 0; i < kLoopFrames; ++i) out.push_back(seq.render(i, false, false));
    return out;
  }();
  return cache;
}

struct MonoRun {
  std::vector<TrackingState> states;
  Trajectory estimate, keyFrames, groundTruth;
  SlamStats stats;
  std::size_t loadedKeyFrames = 0;
};

struct MonoSpec {
  bool localisationOnly = false;
  std::optional<fs::path> loadMap, saveMap;
  int firstFrame = 0;
  bool threaded = false;         // mapping and loop closing on their own threads
  std::optional<double> fps;     // instead of the sequence's
};

MonoRun runMono(const synth::SynthOptions& options, const std::vector<synth::SynthFrame>& frames,
                const MonoSpec& spec = {}) {
  synth::SyntheticSequence seq(options);
  OrbParams orb;
  orb.features = 1000;
  SlamOptions slamOptions;
  slamOptions.deterministic = !spec.threaded;
  slamOptions.localisationOnly = spec.localisationOnly;
  slamOptions.fps = spec.fps.value_or(options.fps);
  Slam<Monocular> slam(seq.camera(), orb, test::sharedVocabulary(), slamOptions);
  MonoRun run;
  if (spec.loadMap) {
    slam.core().loadMap(*spec.loadMap);
    run.loadedKeyFrames = slam.core().loadedKeyFrames();
  }
  for (std::size_t i = static_cast<std::size_t>(spec.firstFrame); i < frames.size(); ++i) {
    const synth::SynthFrame& f = frames[i];
    const double t = seq.timestamp(f.index);
    run.groundTruth.push_back({t, f.pose});
    run.states.push_back(slam.track(test::syntheticInput<Monocular>(f, t)).state);
  }
  slam.shutdown();
  if (spec.saveMap) slam.core().saveMap(*spec.saveMap);
  run.estimate = slam.trajectory();
  run.keyFrames = slam.keyFrameTrajectory();
  run.stats = slam.stats();
  return run;
}

std::string waits(const SlamStats& s) {
  std::string out;
  for (const auto& [reason, frames] : s.initialisationWaits) out += reason + " " + std::to_string(frames) + "; ";
  return out;
}

TEST(MonocularSlam, SyntheticLoopInitialisesEarlyAndTracksUnderOnePercentOfPath) {
  const MonoRun run = runMono(loopOptions(), loopFrames());
  ASSERT_TRUE(run.stats.initialisedAtFrame.has_value()) << waits(run.stats);
  const std::uint64_t start = *run.stats.initialisedAtFrame;
  const eval::AteResult ate = eval::computeAte(run.groundTruth, run.estimate, {eval::Alignment::Sim3, 0.001});
  const eval::AteResult kfAte = eval::computeAte(run.groundTruth, run.keyFrames, {eval::Alignment::Sim3, 0.001});
  const double length = pathLength(run.groundTruth);
  std::cout << "[mono] synthetic loop: initialised at frame " << start << " (" << waits(run.stats) << "), "
            << run.stats.tracked << "/" << run.stats.frames << " tracked, " << run.stats.keyFrames
            << " keyframes; ATE (Sim3) " << ate.stats.rmse * 1000 << " mm, keyframes " << kfAte.stats.rmse * 1000
            << " mm, path " << length << " m\n";
  EXPECT_LT(start, 30u);
  for (std::size_t i = start; i < run.states.size(); ++i) EXPECT_EQ(run.states[i], TrackingState::Ok) << "frame " << i;
  // The first keyframe is tracked too (the reference of the accepted pair).
  EXPECT_GE(run.stats.tracked, run.stats.frames - start);
  EXPECT_LT(ate.stats.rmse, 0.01 * length);
}

// The first `count` frames of the shared 320x240 loop with image noise (slam_test_util.hpp),
// seed 41.
struct LowResolutionLoop {
  synth::SynthOptions options;
  std::vector<synth::SynthFrame> frames;
};
LowResolutionLoop lowResolutionNoisyLoop(int count) {
  LowResolutionLoop loop{test::loopSequence(41), {}};
  synth::SyntheticSequence seq(loop.options);
  for (int i = 0; i < count; ++i) loop.frames.push_back(seq.render(i, false, false));
  return loop;
}

// At 320x240 with noise the finest level keeps few repeatable corners: the windowed matches
// fall under 100 within 5-8 frames of a reference, and under so little parallax H and F explain
// the matches alike (R_H 0.46-0.49), so H won by the paper's 0.45 and its two-fold plane
// ambiguity refused every attempt (seed 41: initialised at frame 66). Falling back to F's
// reconstruction on such a narrow, ambiguous H win (two_view.hpp) initialises it early.
TEST(MonocularSlam, LowResolutionLoopInitialisesWithinThirtyFrames) {
  const auto [options, frames] = lowResolutionNoisyLoop(30);
  const MonoRun run = runMono(options, frames);
  std::cout << "[mono] 320x240 loop, seed 41: initialised at frame "
            << (run.stats.initialisedAtFrame ? std::to_string(*run.stats.initialisedAtFrame) : "never") << " ("
            << waits(run.stats) << ")\n";
  ASSERT_TRUE(run.stats.initialisedAtFrame.has_value()) << waits(run.stats);
  EXPECT_LT(*run.stats.initialisedAtFrame, 30u);
  for (std::size_t i = *run.stats.initialisedAtFrame; i < run.states.size(); ++i)
    EXPECT_EQ(run.states[i], TrackingState::Ok) << "frame " << i;
}

// Threaded, tracking must not run on against a keyframe mapping has not finished with: on a
// slow machine (ThreadSanitizer; one core shared with a busy loop) the map shrank several-fold
// within 30 frames of initialisation and the loop closed with a Sim(3) scale of 0.01-0.14. The
// frames are fed as fast as tracking takes them, and a frame rate of 1000 Hz leaves no time in
// the frame period, as there: a wait bounded by the period (a live camera's) would give mapping
// nothing. The scale of the last 30 frames must stay that of the first 30.
TEST(MonocularSlam, ThreadedTrackingWithNoTimeToSpareKeepsTheScale) {
  const auto [options, frames] = lowResolutionNoisyLoop(90);
  const MonoRun run = runMono(options, frames, {.threaded = true, .fps = 1000.0});
  ASSERT_TRUE(run.stats.initialisedAtFrame.has_value()) << waits(run.stats);
  const std::size_t start = *run.stats.initialisedAtFrame;
  for (std::size_t i = start; i < run.states.size(); ++i) EXPECT_EQ(run.states[i], TrackingState::Ok) << "frame " << i;
  ASSERT_GE(run.estimate.size(), 60u);
  // Each stretch Sim(3)-aligned on its own: the alignment's scale is ground truth over estimate.
  const auto stretchScale = [&](std::size_t from, std::size_t to) {
    const Trajectory part(run.estimate.begin() + static_cast<std::ptrdiff_t>(from),
                          run.estimate.begin() + static_cast<std::ptrdiff_t>(to));
    return eval::computeAte(run.groundTruth, part, {eval::Alignment::Sim3, 0.001}).alignment.scale();
  };
  const std::size_t n = run.estimate.size();
  const double drift = stretchScale(0, 30) / stretchScale(n - 30, n);
  const double ate = eval::computeAte(run.groundTruth, run.estimate, {eval::Alignment::Sim3, 0.001}).stats.rmse;
  std::cout << "[mono] threaded, no time to spare: initialised at frame " << start << ", " << run.stats.tracked << "/"
            << run.stats.frames << " tracked; scale last 30 / first 30 " << drift << ", ATE (Sim3) " << ate * 1000
            << " mm over " << pathLength(run.groundTruth) << " m\n";
  EXPECT_GT(drift, 0.8);
  EXPECT_LT(drift, 1.25);
  EXPECT_LT(ate, 0.01 * pathLength(run.groundTruth));
}

TEST(MonocularSlam, DeterministicModeIsBitIdentical) {
  const std::vector<synth::SynthFrame> frames(loopFrames().begin(), loopFrames().begin() + 60);
  const MonoRun a = runMono(loopOptions(), frames);
  const MonoRun b = runMono(loopOptions(), frames);
  ASSERT_GT(a.estimate.size(), 20u);
  EXPECT_TRUE(identical(a.estimate, b.estimate));
  EXPECT_TRUE(identical(a.keyFrames, b.keyFrames));
}

TEST(MonocularSlam, SavedMapLoadsAndLocalises) {
  const fs::path file = fs::temp_directory_path() / ("orbis_mono_" + std::to_string(::getpid()) + ".map");
  const std::vector<synth::SynthFrame> frames(loopFrames().begin(), loopFrames().begin() + 80);
  const MonoRun mapping = runMono(loopOptions(), frames, {.saveMap = file});
  ASSERT_TRUE(fs::exists(file));
  // A fresh system, localisation only, on frames the map has seen (from frame 30 on).
  const MonoRun localising = runMono(loopOptions(), frames, {.localisationOnly = true, .loadMap = file, .firstFrame = 30});
  const auto firstOk = std::find(localising.states.begin(), localising.states.end(), TrackingState::Ok);
  std::cout << "[mono] map reuse: " << mapping.stats.keyFrames << " keyframes saved, " << localising.loadedKeyFrames
            << " loaded; localising " << localising.stats.tracked << "/" << localising.stats.frames
            << " tracked, first at frame " << 30 + (firstOk - localising.states.begin()) << "\n";
  EXPECT_EQ(localising.loadedKeyFrames, mapping.stats.keyFrames);
  EXPECT_EQ(localising.stats.keyFrames, mapping.stats.keyFrames);  // no keyframe added
  EXPECT_LT(firstOk - localising.states.begin(), 3);
  EXPECT_GE(localising.stats.tracked + 3, localising.stats.frames);
  // Tracked against the map in its own (arbitrary) scale: the estimate matches the ground truth
  // up to a similarity as well as the mapping run did.
  const double mappingAte = eval::computeAte(mapping.groundTruth, mapping.estimate, {eval::Alignment::Sim3, 0.001}).stats.rmse;
  const double localisingAte =
      eval::computeAte(localising.groundTruth, localising.estimate, {eval::Alignment::Sim3, 0.001}).stats.rmse;
  EXPECT_LT(localisingAte, 2 * mappingAte + 0.005);
  fs::remove(file);
}

// A degenerate motion or view must not start a map: initialisation waits and says why.
void checkNeverInitialises(const synth::SynthOptions& options, const char* name, const std::string& reason) {
  const MonoRun run = runMono(options, render(options));
  std::cout << "[mono] " << name << ": " << (run.stats.initialisedAtFrame ? "initialised" : "not initialised")
            << "; frames waiting: " << waits(run.stats) << "\n";
  EXPECT_FALSE(run.stats.initialisedAtFrame.has_value());
  EXPECT_EQ(run.stats.keyFrames, 0u);
  EXPECT_EQ(run.stats.tracked, 0u);
  EXPECT_GT(run.stats.initialisationWaits.count(reason), 0u) << waits(run.stats);
}

TEST(MonocularSlam, StaticCameraDoesNotInitialise) {
  synth::SynthOptions o = monoOptions(30, 3);
  o.path.motion = synth::PathMotion::Static;
  checkNeverInitialises(o, "static camera", "low parallax");
}

TEST(MonocularSlam, PureRotationDoesNotInitialise) {
  // 30 frames of a 300-frame turn: 36 degrees about the vertical, no translation.
  synth::SynthOptions o = monoOptions(300, 3);
  o.path.motion = synth::PathMotion::PureRotation;
  synth::SyntheticSequence seq(o);
  std::vector<synth::SynthFrame> frames;
  for (int i = 0; i < 30; ++i) frames.push_back(seq.render(i, false, false));
  const MonoRun run = runMono(o, frames);
  std::cout << "[mono] pure rotation: " << (run.stats.initialisedAtFrame ? "initialised" : "not initialised")
            << "; frames waiting: " << waits(run.stats) << "\n";
  EXPECT_FALSE(run.stats.initialisedAtFrame.has_value());
  EXPECT_EQ(run.stats.keyFrames, 0u);
}

TEST(MonocularSlam, TexturelessViewDoesNotInitialise) {
  synth::SynthOptions o = monoOptions(20, 3);
  o.flatStart = 0;
  o.flatCount = 20;
  const MonoRun run = runMono(o, render(o));
  std::cout << "[mono] textureless view: " << (run.stats.initialisedAtFrame ? "initialised" : "not initialised")
            << "; frames waiting: " << waits(run.stats) << "\n";
  EXPECT_FALSE(run.stats.initialisedAtFrame.has_value());
  ASSERT_GT(run.stats.initialisationWaits.count("too few keypoints"), 0u) << waits(run.stats);
  EXPECT_EQ(run.stats.initialisationWaits.at("too few keypoints"), 20u);
}

}  // namespace
