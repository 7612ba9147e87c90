// Relocalisation, localisation-only mode and map files, end to end on a synthetic loop (issue 8):
//  - a segment of black frames: tracking is lost during it, relocalises within 10 frames after
//    the images return, and the final ATE stays within 20% of the run without the gap;
//  - a saved map loaded into a fresh system in localisation-only mode on the same frames: no
//    keyframe added, every frame tracked against the map, ATE no worse than the mapping run.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <optional>

#include <unistd.h>

#include "orbis/eval/metrics.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;

constexpr int kFrames = 150;

synth::SynthOptions loopOptions() {
  synth::SynthOptions o;
  o.frames = kFrames;
  o.width = 640;
  o.height = 480;
  o.fx = 500;
  o.noiseSigma = 2.0;
  o.seed = 21;
  o.threads = 2;
  return o;
}

// Rendered once per process and sensor: every test replays the same frames.
template <class Sensor>
const std::vector<synth::SynthFrame>& frames() {
  static const std::vector<synth::SynthFrame> cache = [] {
    synth::SyntheticSequence seq(loopOptions());
    std::vector<synth::SynthFrame> out;
    for (int i = 0; i < seq.size(); ++i) out.push_back(seq.render(i, !Sensor::kDepthFromSensor, Sensor::kDepthFromSensor));
    return out;
  }();
  return cache;
}

struct RunSpec {
  int blackStart = -1, blackCount = 0;
  bool localisationOnly = false;
  std::optional<fs::path> loadMap, saveMap;
};

struct RunResult {
  std::vector<TrackingState> states;
  Trajectory estimate, groundTruth;
  SlamStats stats;
  RelocalisationStats relocalisation;
  std::size_t loadedKeyFrames = 0;
  double ate = 0;
};

template <class Sensor>
RunResult run(const RunSpec& spec) {
  const synth::SynthOptions options = loopOptions();
  synth::SyntheticSequence seq(options);
  const auto camera = test::syntheticCamera<Sensor>(seq, options.baseline);
  OrbParams orb;
  orb.features = 1000;
  SlamOptions slamOptions;
  slamOptions.deterministic = true;
  slamOptions.loopClosing = false;  // the loop of this path would hide the effect under test
  slamOptions.localisationOnly = spec.localisationOnly;
  slamOptions.fps = options.fps;
  Slam<Sensor> slam(camera, orb, test::sharedVocabulary(), slamOptions);
  RunResult r;
  if (spec.loadMap) {
    slam.core().loadMap(*spec.loadMap);
    r.loadedKeyFrames = slam.core().loadedKeyFrames();
  }
  for (const synth::SynthFrame& cached : frames<Sensor>()) {
    synth::SynthFrame f = cached;
    const double t = seq.timestamp(f.index);
    r.groundTruth.push_back({t, f.pose});
    if (f.index >= spec.blackStart && f.index < spec.blackStart + spec.blackCount) {
      // As the synth's black frames: covered camera, zero depth. New buffers: the cache shares its.
      auto black = [](const cv::Mat& m) { return m.empty() ? m : cv::Mat(m.size(), m.type(), cv::Scalar::all(0)); };
      f.left = black(f.left);
      f.right = black(f.right);
      f.depth = black(f.depth);
    }
    r.states.push_back(slam.track(test::syntheticInput<Sensor>(f, t)).state);
  }
  slam.shutdown();
  if (spec.saveMap) slam.core().saveMap(*spec.saveMap);
  r.estimate = slam.trajectory();
  r.stats = slam.stats();
  r.relocalisation = slam.core().relocalisationStats();
  r.ate = eval::computeAte(r.groundTruth, r.estimate, {eval::Alignment::SE3, 0.001}).stats.rmse;
  return r;
}

fs::path tempFile(const std::string& name) {
  return fs::temp_directory_path() / ("orbis_reloc_" + std::to_string(::getpid()) + "_" + name);
}

template <class Sensor>
void checkBlackGap(const char* name) {
  // The images return where the map already is (the path nears its start again): relocalisation
  // needs a keyframe that saw the view. Mid-loop, 10 frames turn the camera 24 degrees, away from
  // the last keyframe's view, and it would (correctly) stay lost until the path comes back.
  constexpr int kBlackStart = 125, kBlackCount = 10;
  const RunResult reference = run<Sensor>({});
  const RunResult gap = run<Sensor>({kBlackStart, kBlackCount});
  ASSERT_EQ(gap.states.size(), static_cast<std::size_t>(kFrames));
  // Tracked up to the gap, lost throughout it.
  for (int i = 1; i < kBlackStart; ++i) EXPECT_EQ(gap.states[i], TrackingState::Ok) << "frame " << i;
  for (int i = kBlackStart; i < kBlackStart + kBlackCount; ++i)
    EXPECT_EQ(gap.states[i], TrackingState::Lost) << "frame " << i;
  int firstBack = -1;
  for (int i = kBlackStart + kBlackCount; i < kFrames && firstBack < 0; ++i)
    if (gap.states[i] == TrackingState::Ok) firstBack = i;
  const int delay = firstBack - (kBlackStart + kBlackCount);
  std::cout << "[reloc] " << name << ": lost at frame " << kBlackStart << ", images back at "
            << kBlackStart + kBlackCount << ", relocalised at " << firstBack << " (" << gap.relocalisation.successes
            << " of " << gap.relocalisation.attempts << " attempts); ATE " << gap.ate * 1000 << " mm vs "
            << reference.ate * 1000 << " mm without the gap (" << gap.stats.tracked << " / "
            << reference.stats.tracked << " frames tracked)\n";
  ASSERT_GE(firstBack, 0) << "never relocalised";
  EXPECT_LT(delay, 10);
  EXPECT_GE(gap.relocalisation.successes, 1u);
  // Once back, a few frames may drop again while the local map rebuilds (the tracker asks for 50
  // inliers just after a relocalisation), but it ends tracked.
  const auto lostAfter = std::count(gap.states.begin() + firstBack, gap.states.end(), TrackingState::Lost);
  std::cout << "[reloc] " << name << ": " << lostAfter << " frames lost again after relocalising\n";
  EXPECT_LE(lostAfter, 5);
  EXPECT_EQ(gap.states.back(), TrackingState::Ok);
  EXPECT_LE(gap.ate, 1.2 * reference.ate);
}

TEST(Relocalisation, RgbdRecoversAfterBlackFrames) { checkBlackGap<Rgbd>("RGB-D"); }
TEST(Relocalisation, StereoRecoversAfterBlackFrames) { checkBlackGap<Stereo>("stereo"); }

TEST(MapReuse, SavedMapLoadsIntoLocalisationOnlyRunWithoutNewKeyFrames) {
  const fs::path file = tempFile("rgbd.map");
  const RunResult mapping = run<Rgbd>({.saveMap = file});
  ASSERT_TRUE(fs::exists(file));
  const RunResult localising = run<Rgbd>({.localisationOnly = true, .loadMap = file});
  std::cout << "[reloc] map reuse: mapping run " << mapping.stats.keyFrames << " keyframes, ATE "
            << mapping.ate * 1000 << " mm; localisation run on the loaded map: " << localising.loadedKeyFrames
            << " keyframes loaded, " << localising.stats.keyFrames << " after, " << localising.stats.tracked << " / "
            << localising.stats.frames << " frames tracked against the map (first relocalisation at frame "
            << (std::find(localising.states.begin(), localising.states.end(), TrackingState::Ok) -
                localising.states.begin())
            << "), ATE " << localising.ate * 1000 << " mm\n";
  EXPECT_EQ(localising.loadedKeyFrames, mapping.stats.keyFrames);
  EXPECT_EQ(localising.stats.keyFrames, mapping.stats.keyFrames);  // no keyframe added
  EXPECT_EQ(localising.stats.mapPoints, mapping.stats.mapPoints);
  EXPECT_EQ(localising.states.front(), TrackingState::Ok);  // relocalised on the very first frame
  EXPECT_EQ(localising.stats.tracked, localising.stats.frames);
  EXPECT_LE(localising.ate, mapping.ate);
  fs::remove(file);
}

TEST(MapReuse, MapOfAnotherSensorIsRefused) {
  const fs::path file = tempFile("stereo_only.map");
  {
    synth::SyntheticSequence seq(loopOptions());
    Slam<Stereo> stereo(RectifiedStereoCamera<double>(seq.camera(), loopOptions().baseline), OrbParams{}, test::sharedVocabulary(),
                        {.deterministic = true, .loopClosing = false});
    stereo.shutdown();
    stereo.core().saveMap(file);
  }
  synth::SyntheticSequence seq(loopOptions());
  Slam<Rgbd> rgbd(RgbdCamera<double>(seq.camera(), loopOptions().baseline, 1.0), OrbParams{}, test::sharedVocabulary(),
                  {.deterministic = true});
  try {
    rgbd.core().loadMap(file);
    ADD_FAILURE() << "a stereo map loaded into an RGB-D system";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("map made with sensor stereo"), std::string::npos) << e.what();
  }
  fs::remove(file);
}

}  // namespace
