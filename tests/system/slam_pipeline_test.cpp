// End-to-end tests of Slam<Sensor>: synthetic sequences with exact ground truth (always run) and
// the real benchmark slices (skipped when ../shared/datasets is absent).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "orbis/eval/metrics.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"
#include "test_data.hpp"

namespace {

namespace fs = std::filesystem;
using namespace orbis;
using test::identical;
using test::pathLength;

synth::SynthOptions smallLoop(std::uint64_t seed) {
  synth::SynthOptions o;
  o.frames = 150;
  o.noiseSigma = 2.0;
  o.depthNoise = 0.0014;  // Kinect-like (RGB-D runs only read depth)
  o.seed = seed;
  o.threads = 2;
  return o;
}

struct SyntheticRun {
  Trajectory estimate, groundTruth;
  SlamStats stats;
};

template <class Sensor>
SyntheticRun runSynthetic(const synth::SynthOptions& options, const std::vector<int>& corrupt = {}) {
  synth::SyntheticSequence seq(options);
  const auto camera = test::syntheticCamera<Sensor>(seq, options.baseline);
  OrbParams orb;
  orb.features = 1000;
  SlamOptions slamOptions;
  slamOptions.deterministic = true;
  slamOptions.loopClosing = false;
  slamOptions.fps = options.fps;
  Slam<Sensor> slam(camera, orb, test::sharedVocabulary(), slamOptions);
  SyntheticRun run;
  for (int i = 0; i < seq.size(); ++i) {
    synth::SynthFrame f = seq.render(i, !Sensor::kDepthFromSensor, Sensor::kDepthFromSensor);
    run.groundTruth.push_back({seq.timestamp(i), f.pose});
    const bool black = std::find(corrupt.begin(), corrupt.end(), i) != corrupt.end();
    if (black) {
      f.left.setTo(0);
      if (!f.right.empty()) f.right.setTo(0);
      if (!f.depth.empty()) f.depth.setTo(0);
    }
    slam.track(test::syntheticInput<Sensor>(f, seq.timestamp(i)));
  }
  slam.shutdown();
  run.estimate = slam.trajectory();
  run.stats = slam.stats();
  return run;
}

template <class Sensor>
void checkSynthetic(const char* name) {
  const SyntheticRun run = runSynthetic<Sensor>(smallLoop(3));
  EXPECT_EQ(run.stats.lost, 0u);
  EXPECT_EQ(run.stats.tracked, run.stats.frames);
  const eval::AteResult ate = eval::computeAte(run.groundTruth, run.estimate, {eval::Alignment::SE3, 0.001});
  const double length = pathLength(run.groundTruth);
  std::cout << "[slam] synthetic " << name << ": ATE " << ate.stats.rmse * 1000 << " mm over " << ate.stats.count
            << " poses, path " << length << " m (" << 100 * ate.stats.rmse / length << "%), " << run.stats.keyFrames
            << " keyframes\n";
  EXPECT_LT(ate.stats.rmse, 0.01 * length);  // issue 7: under 1% of the path before any loop closure
}

TEST(SlamPipeline, SyntheticRgbdTracksEveryFrameUnderOnePercentOfPath) { checkSynthetic<Rgbd>("RGB-D"); }
TEST(SlamPipeline, SyntheticStereoTracksEveryFrameUnderOnePercentOfPath) { checkSynthetic<Stereo>("stereo"); }

TEST(SlamPipeline, DeterministicModeIsBitIdentical) {
  auto options = smallLoop(5);
  options.frames = 60;
  const SyntheticRun a = runSynthetic<Rgbd>(options);
  const SyntheticRun b = runSynthetic<Rgbd>(options);
  ASSERT_FALSE(a.estimate.empty());
  EXPECT_TRUE(identical(a.estimate, b.estimate));
}

TEST(SlamPipeline, BlackAndZeroDepthFramesAreSurvived) {
  auto options = smallLoop(7);
  options.frames = 60;
  // Frames 20-22 black with zero depth: tracking may be lost there; the process and map are not.
  const SyntheticRun run = runSynthetic<Rgbd>(options, {20, 21, 22});
  EXPECT_EQ(run.stats.frames, 60u);
  EXPECT_GE(run.stats.tracked, 20u);
  EXPECT_GE(run.stats.keyFrames, 1u);
}

RunReport runReal(DatasetReader& dataset, const fs::path& out) {
  RunOptions options;
  options.vocabulary = defaultVocabularyPath();
  options.outDir = out;
  options.deterministic = true;
  options.progress = false;
  return runDataset(dataset, options);
}

TEST(SlamPipeline, TumTeddyRgbdDeterministic) {
  ORBIS_REQUIRE_DATASET(root, "tum_fr3_teddy_200");
  auto dataset = openDataset(DatasetKind::TumRgbd, root);
  const fs::path out = fs::temp_directory_path() / "orbis_teddy_a";
  const RunReport a = runReal(*dataset, out);
  ASSERT_TRUE(a.ateRmse.has_value());
  std::cout << "[slam] TUM teddy RGB-D: ATE " << *a.ateRmse * 1000 << " mm over " << a.ateMatched << " poses, "
            << a.stats.tracked << "/" << a.stats.frames << " tracked, " << a.stats.keyFrames << " keyframes\n";
  EXPECT_EQ(a.stats.lost, 0u);
  // 4.6 mm measured (4.3-4.7 over feature budgets 900-1100); ORB-SLAM2's stereo residual for the
  // depth readings gave 6.6 mm here, so 6 mm catches losing the disparity residual.
  EXPECT_LT(*a.ateRmse, 0.006);
  const fs::path out2 = fs::temp_directory_path() / "orbis_teddy_b";
  runReal(*dataset, out2);
  EXPECT_EQ(test::fileBytes(out / "trajectory.txt"), test::fileBytes(out2 / "trajectory.txt"));
  for (const char* f : {"keyframes.txt", "report.json", "map.ply", "overview.png"}) EXPECT_TRUE(fs::exists(out / f)) << f;
}

TEST(SlamPipeline, EurocStereoDeterministic) {
  ORBIS_REQUIRE_DATASET(root, "euroc_V1_01_easy_95");
  auto dataset = openDataset(DatasetKind::Euroc, root);
  const RunReport r = runReal(*dataset, fs::temp_directory_path() / "orbis_euroc");
  ASSERT_TRUE(r.ateRmse.has_value());
  std::cout << "[slam] EuRoC V1_01 stereo: ATE " << *r.ateRmse * 1000 << " mm over " << r.ateMatched << " poses\n";
  EXPECT_EQ(r.stats.lost, 0u);
  EXPECT_LT(*r.ateRmse, 0.003);
}

}  // namespace
