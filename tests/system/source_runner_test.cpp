// runSource (system/dataset_runner.hpp): an image folder goes the dataset's way through the
// runner (the same trajectory, byte for byte), --resize scales images and intrinsics and says
// so, a stop request ends the run with every output written and the report marked interrupted,
// and a source without calibration is an error that says how to get one.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "orbis/synth/writers.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/util/error.hpp"
#include "slam_test_util.hpp"
#include "test_data.hpp"

namespace {

using namespace orbis;
namespace fs = std::filesystem;

class SourceRunnerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("orbis_source_runner_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    synth::SynthOptions o = test::loopSequence(4);
    o.frames = 50;
    synth::SyntheticSequence sequence(o);
    synth::writeSynthSequence(sequence, synth::SynthLayout::Tum, dir_ / "sequence");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static RunOptions options(const std::string& out) {
    RunOptions o;
    o.settings = dir_ / "sequence" / "settings_mono.yaml";
    o.vocabulary = defaultVocabularyPath();
    o.outDir = dir_ / out;
    o.deterministic = true;
    o.progress = false;
    return o;
  }
  static std::unique_ptr<FrameSource> folder() {
    SourceOptions o;
    o.timesFile = dir_ / "sequence" / "rgb.txt";
    return openImageFolderSource(dir_ / "sequence" / "rgb", o);
  }
  static inline fs::path dir_;
};

TEST_F(SourceRunnerTest, AnImageFolderTracksAsTheDatasetDoes) {
  DatasetOptions mono;
  mono.sensor = SensorKind::Monocular;
  auto dataset = openDataset(DatasetKind::TumRgbd, dir_ / "sequence", mono);
  const RunReport fromDataset = runDataset(*dataset, options("dataset"));
  auto source = folder();
  RunOptions o = options("folder");
  o.groundTruth = dir_ / "sequence" / "groundtruth.txt";
  const RunReport fromFolder = runSource(*source, o);
  EXPECT_GT(fromFolder.stats.tracked, 5u);
  EXPECT_EQ(fromFolder.stats.tracked, fromDataset.stats.tracked);
  EXPECT_EQ(test::fileBytes(dir_ / "folder" / "trajectory.txt"), test::fileBytes(dir_ / "dataset" / "trajectory.txt"));
  ASSERT_TRUE(fromFolder.ateRmse.has_value()) << "--groundtruth gives the ATE";
  EXPECT_EQ(fromFolder.ateAlignment, "sim3");
  EXPECT_EQ(*fromFolder.ateRmse, *fromDataset.ateRmse);
  EXPECT_FALSE(fromFolder.live);
  EXPECT_FALSE(fromFolder.interrupted);
  // Every frame tracked (state OK) has its latency; the frame that started the map is in the
  // trajectory without being tracked.
  EXPECT_GT(fromFolder.latency.count, 0u);
  EXPECT_LE(fromFolder.latency.count, fromFolder.stats.tracked);
  const std::string report = test::fileBytes(dir_ / "folder" / "report.json");
  EXPECT_NE(report.find("\"name\":\"images:"), std::string::npos) << report;
  EXPECT_NE(report.find("\"interrupted\":false"), std::string::npos);
}

TEST_F(SourceRunnerTest, ResizeScalesImagesAndIntrinsicsAndSaysSo) {
  auto source = folder();
  RunOptions o = options("resized");
  o.resizeWidth = 480;  // up: the extractor sees 480 x 360 images, the camera's fx is 375
  o.maxFrames = 30;
  const RunReport r = runSource(*source, o);
  EXPECT_EQ(r.inputWidth, 320);
  EXPECT_EQ(r.resizedWidth, 480);
  EXPECT_EQ(r.resizedHeight, 360);
  EXPECT_EQ(r.stats.frames, 30u);
  EXPECT_GT(r.stats.tracked, 0u) << "scaled intrinsics that did not match the images would not track";
  EXPECT_NE(test::fileBytes(dir_ / "resized" / "report.json").find("\"resized_to\":[480,360]"), std::string::npos);
}

TEST_F(SourceRunnerTest, AStopRequestEndsTheRunWithEveryOutputWritten) {
  auto source = folder();
  RunOptions o = options("stopped");
  int asked = 0;
  o.stopRequested = [&asked] { return ++asked > 25; };
  const RunReport r = runSource(*source, o);
  EXPECT_TRUE(r.interrupted);
  EXPECT_LT(r.stats.frames, 50u);
  EXPECT_GT(r.stats.frames, 0u);
  for (const char* name : {"trajectory.txt", "keyframes.txt", "map.ply", "overview.png"})
    EXPECT_TRUE(fs::is_regular_file(dir_ / "stopped" / name)) << name;
  EXPECT_NE(test::fileBytes(dir_ / "stopped" / "report.json").find("\"interrupted\":true"), std::string::npos);
}

TEST_F(SourceRunnerTest, CalibrationMissingOrForAnotherAspectIsAnError) {
  auto source = folder();
  RunOptions o = options("uncalibrated");
  o.settings.reset();
  try {
    runSource(*source, o);
    ADD_FAILURE() << "ran without calibration";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("orbis calibrate"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--settings"), std::string::npos) << e.what();
  }
  // The rendered settings are for 320 x 240: written for 640 x 480 (twice fx, cx, cy) they still
  // fit, scaled, with a warning; for 320 x 180 (another aspect) they do not.
  std::ifstream in(dir_ / "sequence" / "settings_mono.yaml");
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const auto rewrite = [&](const fs::path& file, const std::map<std::string, std::string>& values) {
    std::istringstream lines(text);
    std::ofstream out(file);
    for (std::string line; std::getline(lines, line);) {
      const std::string key = line.substr(0, line.find(':'));
      out << (values.count(key) ? key + ": " + values.at(key) : line) << "\n";
    }
  };
  rewrite(dir_ / "double.yaml", {{"Camera.fx", "500"}, {"Camera.fy", "500"}, {"Camera.cx", "319.5"}, {"Camera.cy", "239.5"},
                                 {"Camera.width", "640"}, {"Camera.height", "480"}});
  rewrite(dir_ / "wide.yaml", {{"Camera.height", "180"}});
  auto doubled = folder();
  o.settings = dir_ / "double.yaml";
  o.maxFrames = 30;
  o.outDir = dir_ / "double";
  const RunReport scaled = runSource(*doubled, o);
  EXPECT_GT(scaled.stats.tracked, 0u);
  EXPECT_TRUE(std::any_of(scaled.warnings.begin(), scaled.warnings.end(),
                          [](const std::string& w) { return w.find("intrinsics scaled to the frames") != std::string::npos; }));
  auto again = folder();
  o.settings = dir_ / "wide.yaml";
  EXPECT_THROW(runSource(*again, o), Error);
}

}  // namespace
