// Synthetic sequences written in the three dataset layouts and read back through the dataset
// adapters and the settings reader: the same frames, depth, ground truth and calibration.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>
#include <variant>

#include <unistd.h>

#include <opencv2/core.hpp>

#include "orbis/adapters/dataset.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/synth/writers.hpp"
#include "orbis/util/error.hpp"

namespace orbis::synth {
namespace {

namespace fs = std::filesystem;

SynthOptions tinyOptions() {
  SynthOptions o;
  o.frames = 6;
  o.width = 160;
  o.height = 120;
  o.fx = 120.0;
  o.baseline = 0.15;
  o.noiseSigma = 2.0;
  o.blackStart = 4;
  o.blackCount = 1;
  o.seed = 11;
  return o;
}

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("orbis_synth_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

double poseDistance(const SE3d& a, const SE3d& b) {
  const SE3d d = a.inverse() * b;
  return d.translation().norm() + d.so3().log().norm();
}

void expectSameImage(const cv::Mat& written, const cv::Mat& read, const std::string& what) {
  ASSERT_FALSE(read.empty()) << what;
  cv::Mat grey = read;
  if (read.channels() == 3) cv::extractChannel(read, grey, 0);
  ASSERT_EQ(grey.size(), written.size()) << what;
  EXPECT_EQ(cv::norm(written, grey, cv::NORM_INF), 0.0) << what;
}

class SynthLayoutTest : public ::testing::TestWithParam<SynthLayout> {};

TEST_P(SynthLayoutTest, AdaptersReadBackFramesGroundTruthAndCalibration) {
  const SynthLayout layout = GetParam();
  const fs::path dir = freshDir(std::string(toString(layout)));
  const SynthOptions o = tinyOptions();
  SyntheticSequence seq(o);
  int progress = 0;
  const SynthWriteResult written = writeSynthSequence(seq, layout, dir, [&](int done) { progress = done; });
  EXPECT_EQ(progress, o.frames);
  EXPECT_EQ(written.frames, o.frames);
  EXPECT_EQ(written.blackFrames, 1);

  const DatasetKind kind = layout == SynthLayout::Tum ? DatasetKind::TumRgbd
                           : layout == SynthLayout::Euroc ? DatasetKind::Euroc : DatasetKind::Kitti;
  EXPECT_EQ(detectDatasetKind(dir), kind);
  DatasetOptions options;
  options.strict = true;  // a missing right image or depth map would throw
  options.tumVirtualBaseline = o.baseline;
  const auto reader = openDataset(kind, dir, options);
  ASSERT_EQ(reader->size(), static_cast<std::size_t>(o.frames));

  // Ground truth: world-frame T_wc for TUM and EuRoC, relative to frame 0 for KITTI.
  const Trajectory& gt = reader->groundTruth();
  ASSERT_EQ(gt.size(), static_cast<std::size_t>(o.frames));
  const SE3d firstInverse = seq.pose(0).inverse();
  for (int i = 0; i < o.frames; ++i) {
    const SE3d expected = layout == SynthLayout::Kitti ? firstInverse * seq.pose(i) : seq.pose(i);
    EXPECT_LT(poseDistance(gt[static_cast<std::size_t>(i)].pose, expected), 1e-6) << "frame " << i;
  }

  for (int i = 0; i < o.frames; ++i) {
    const SynthFrame f = seq.render(i, layout != SynthLayout::Tum, layout == SynthLayout::Tum);
    const DatasetFrame d = reader->frame(static_cast<std::size_t>(i));
    EXPECT_TRUE(d.warnings.empty()) << "frame " << i;
    const double dt = layout == SynthLayout::Kitti ? seq.timestamp(i) - seq.timestamp(0) : seq.timestamp(i);
    EXPECT_NEAR(d.timestamp, dt, 2e-6) << "frame " << i;
    expectSameImage(f.left, d.left, "left " + std::to_string(i));
    if (layout == SynthLayout::Tum) {
      ASSERT_EQ(d.depth.type(), CV_16UC1);
      // 16-bit PNG at 5000 per metre: a quantisation step of 0.2 mm.
      cv::Mat metres;
      d.depth.convertTo(metres, CV_32F, 1.0 / 5000.0);
      EXPECT_LE(cv::norm(f.depth, metres, cv::NORM_INF), 1.0 / 5000.0 * 0.5 + 1e-6) << "depth " << i;
    } else {
      expectSameImage(f.right, d.right, "right " + std::to_string(i));
    }
  }

  // Calibration through the adapter and through the written settings file.
  const auto check = [&](const PinholeCamera<double>& p) {
    EXPECT_NEAR(p.fx, o.fx, 1e-6);
    EXPECT_NEAR(p.fy, o.fx, 1e-6);
    EXPECT_NEAR(p.cx, 0.5 * o.width, 1e-6);
    EXPECT_NEAR(p.cy, 0.5 * o.height, 1e-6);
  };
  if (layout == SynthLayout::Tum) {
    // The TUM layout has no calibration file: the reader knows only the three Kinects, and the
    // synthetic camera comes from the settings file written beside it.
    EXPECT_THROW(reader->camera(), Error);
  } else {
    std::visit([&](const auto& cam) {
      using C = std::decay_t<decltype(cam)>;
      if constexpr (std::is_same_v<C, PinholeCamera<double>>) {
        ADD_FAILURE() << "a stereo layout read as monocular";
      } else {
        check(cam.pinhole);
        EXPECT_NEAR(cam.baseline, o.baseline, 1e-6);
      }
    }, reader->camera());
  }
  const Settings settings = Settings::load(written.settings);
  EXPECT_EQ(settings.sensor, layout == SynthLayout::Tum ? SensorKind::Rgbd : SensorKind::Stereo);
  std::visit([&](const auto& cam) {
    using C = std::decay_t<decltype(cam)>;
    if constexpr (std::is_same_v<C, KannalaBrandtCamera<double>>) {
      ADD_FAILURE() << "a pinhole sequence's settings describe a fisheye";
    } else if constexpr (!std::is_same_v<C, PinholeCamera<double>>) {
      check(cam.pinhole);
      EXPECT_NEAR(cam.baseline, o.baseline, 1e-9);
    }
  }, settings.camera);
  if (layout == SynthLayout::Tum) EXPECT_DOUBLE_EQ(settings.depthMapFactor, 5000.0);
  const Settings mono = Settings::load(written.settingsMono);
  EXPECT_EQ(mono.sensor, SensorKind::Monocular);
  ASSERT_TRUE(std::holds_alternative<PinholeCamera<double>>(mono.camera));
  check(std::get<PinholeCamera<double>>(mono.camera));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(AllLayouts, SynthLayoutTest,
                         ::testing::Values(SynthLayout::Tum, SynthLayout::Euroc, SynthLayout::Kitti),
                         [](const auto& info) { return std::string(toString(info.param)); });

TEST(SynthWriters, LayoutNamesRoundTripAndBadNamesAreErrors) {
  for (SynthLayout l : {SynthLayout::Tum, SynthLayout::Euroc, SynthLayout::Kitti})
    EXPECT_EQ(parseSynthLayout(toString(l)), l);
  EXPECT_THROW(parseSynthLayout("bag"), Error);
}

TEST(SynthWriters, ExtraFramesContinueThePeriodicPathPastTheLoop) {
  SynthOptions o = tinyOptions();
  o.blackCount = 0;
  o.extraFrames = 3;
  SyntheticSequence seq(o);
  const fs::path dir = freshDir("extra");
  const SynthWriteResult written = writeSynthSequence(seq, SynthLayout::Tum, dir);
  EXPECT_EQ(written.frames, o.frames + o.extraFrames);
  auto reader = openTumRgbd(dir, {});
  ASSERT_EQ(reader->size(), static_cast<std::size_t>(o.frames + o.extraFrames));
  const Trajectory& gt = reader->groundTruth();
  ASSERT_EQ(gt.size(), reader->size());
  // Frame frames + k is taken where frame k was: the path repeats, time goes on.
  for (int k = 0; k < o.extraFrames; ++k) {
    EXPECT_LT(poseDistance(gt[static_cast<std::size_t>(k)].pose, gt[static_cast<std::size_t>(o.frames + k)].pose), 1e-6);
    EXPECT_GT(gt[static_cast<std::size_t>(o.frames + k)].t, gt[static_cast<std::size_t>(o.frames + k - 1)].t);
  }
  fs::remove_all(dir);
}

TEST(SynthWriters, UnwritableDirectoryNamesThePath) {
  SyntheticSequence seq(tinyOptions());
  const fs::path blocker = freshDir("blocker");
  { std::ofstream(blocker) << "a file, not a directory"; }
  try {
    writeSynthSequence(seq, SynthLayout::Kitti, blocker / "out");
    FAIL() << "wrote below a regular file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(blocker.string()), std::string::npos) << e.what();
  }
  fs::remove(blocker);
}

}  // namespace
}  // namespace orbis::synth
