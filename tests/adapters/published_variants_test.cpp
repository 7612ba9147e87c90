// Datasets as their publishers ship them, rendered small: EuRoC's sensor.yaml without OpenCV's
// %YAML:1.0 line, EuRoC ground truth in TUM form, listed PNGs missing or corrupt on disk.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "orbis/adapters/dataset.hpp"
#include "orbis/camera/euroc_calibration.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/util/error.hpp"
#include "rendered_sequence.hpp"

namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class PublishedVariants : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("orbis_variants_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  // A rendered EuRoC-layout stereo sequence (already rectified, as synth writes it): one loop in
  // 150 frames, so consecutive frames overlap as a real camera's do; runs read its first kRunFrames.
  // Rendered once for the suite and copied per test.
  static constexpr std::size_t kRunFrames = 30;
  void renderEuroc() {
    static const fs::path rendered = [] {
      const fs::path dir = fs::temp_directory_path() / ("orbis_variants_euroc_" + std::to_string(::getpid()));
      fs::remove_all(dir);
      orbis::test::renderSmallLoop(orbis::synth::SynthLayout::Euroc, dir, 5);
      return dir;
    }();
    fs::copy(rendered, root_, fs::copy_options::recursive);
  }
  static void TearDownTestSuite() {
    fs::remove_all(fs::temp_directory_path() / ("orbis_variants_euroc_" + std::to_string(::getpid())));
  }

  // What ASL publishes: the file starts with a comment, no "%YAML:1.0" line.
  void dropYamlHeader(const fs::path& sensorYaml) {
    std::string text = readText(sensorYaml);
    ASSERT_EQ(text.rfind("%YAML:1.0\n", 0), 0u) << sensorYaml;
    text.erase(0, text.find('\n') + 1);
    std::ofstream(sensorYaml, std::ios::binary) << text;
  }

  orbis::RunReport run(orbis::DatasetReader& dataset) {
    orbis::RunOptions options;
    options.vocabulary = orbis::defaultVocabularyPath();
    options.outDir = root_ / "out";
    options.deterministic = true;
    options.progress = false;
    options.maxFrames = kRunFrames;
    return orbis::runDataset(dataset, options);
  }

  fs::path frameImage(int camera, std::size_t index) const {
    const fs::path list = root_ / "mav0" / ("cam" + std::to_string(camera)) / "data.csv";
    std::ifstream in(list);
    std::string line;
    std::size_t row = 0;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      if (row++ == index) return list.parent_path() / "data" / line.substr(line.find(',') + 1);
    }
    ADD_FAILURE() << list << " has no row " << index;
    return {};
  }

  fs::path root_;
};

TEST_F(PublishedVariants, EurocSensorYamlWithoutOpenCvHeaderIsReadAndRuns) {
  renderEuroc();
  const fs::path cam0 = root_ / "mav0/cam0/sensor.yaml", cam1 = root_ / "mav0/cam1/sensor.yaml";
  const orbis::CameraCalibration withHeader = orbis::readEurocCalibration(cam0);
  dropYamlHeader(cam0);
  dropYamlHeader(cam1);
  ASSERT_EQ(readText(cam0).find("%YAML"), std::string::npos);

  const orbis::CameraCalibration withoutHeader = orbis::readEurocCalibration(cam0);
  EXPECT_EQ(withoutHeader.intrinsics.fx, withHeader.intrinsics.fx);
  EXPECT_EQ(withoutHeader.intrinsics.width, 320);
  EXPECT_TRUE(withoutHeader.bodyFromCamera.isApprox(withHeader.bodyFromCamera));

  const auto dataset = orbis::openEuroc(root_, {});
  ASSERT_EQ(dataset->size(), 150u);
  const orbis::RunReport report = run(*dataset);
  EXPECT_EQ(report.stats.frames, kRunFrames);
  EXPECT_EQ(report.stats.tracked, kRunFrames);
  ASSERT_TRUE(report.ateRmse.has_value());
  EXPECT_LT(*report.ateRmse, 0.05);
}

TEST_F(PublishedVariants, EurocSensorYamlParseErrorNamesTheLine) {
  fs::create_directories(root_);
  const fs::path file = root_ / "sensor.yaml";
  std::ofstream(file) << "# comment\nintrinsics: [1, 2\nresolution: [752, 480]\n";
  try {
    orbis::readEurocCalibration(file);
    ADD_FAILURE() << "no error";
  } catch (const orbis::Error& e) {
    EXPECT_EQ(e.source(), file.string());
    EXPECT_EQ(e.where().rfind("line ", 0), 0u) << e.what();
  }
  std::ofstream(file) << "- just\n- a list\n";
  EXPECT_THROW(orbis::readEurocCalibration(file), orbis::Error);
  std::ofstream(file) << "intrinsics: {fu: 1}\n";
  EXPECT_THROW(orbis::readEurocCalibration(file), orbis::Error);
}

// evo and hand conversions give the EuRoC ground truth as TUM rows; both name body poses.
TEST_F(PublishedVariants, EurocGroundTruthInTumFormMatchesTheCsv) {
  renderEuroc();
  const fs::path csv = root_ / "mav0/state_groundtruth_estimate0/data.csv";
  const orbis::Trajectory fromCsv = orbis::openEuroc(root_, {})->groundTruth();
  ASSERT_EQ(fromCsv.size(), 150u);
  const orbis::Trajectory body = orbis::readTrajectory(csv, orbis::TrajectoryFormat::Euroc);
  fs::rename(csv, csv.parent_path() / "published.csv");
  for (const fs::path& tumForm : {csv, csv.parent_path() / "data.tum"}) {
    orbis::writeTrajectory(tumForm, body, orbis::TrajectoryFormat::Tum);
    const orbis::Trajectory fromTum = orbis::openEuroc(root_, {})->groundTruth();
    ASSERT_EQ(fromTum.size(), fromCsv.size()) << tumForm;
    for (std::size_t i = 0; i < fromCsv.size(); ++i) {
      EXPECT_NEAR(fromTum[i].t, fromCsv[i].t, 1e-6) << tumForm << " pose " << i;
      EXPECT_LT((fromTum[i].pose.matrix() - fromCsv[i].pose.matrix()).cwiseAbs().maxCoeff(), 1e-6) << tumForm;
    }
    fs::remove(tumForm);
  }
}

// A listed PNG missing or corrupt, in either camera: that frame is skipped with one warning.
TEST_F(PublishedVariants, EurocMissingOrCorruptPngSkipsThatFrameOnly) {
  renderEuroc();
  fs::remove(frameImage(0, 5));
  fs::remove(frameImage(1, 9));
  std::ofstream(frameImage(0, 12), std::ios::binary) << "\x89PNG\r\n\x1a\n truncated";
  std::ofstream(frameImage(1, 15), std::ios::binary) << "";
  orbis::DatasetOptions tolerant;
  tolerant.tolerateBadFrames = true;
  const auto dataset = orbis::openEuroc(root_, tolerant);
  ASSERT_EQ(dataset->size(), 150u);
  const orbis::RunReport report = run(*dataset);
  EXPECT_EQ(report.stats.frames, kRunFrames - 4);
  EXPECT_GE(report.stats.tracked, kRunFrames - 6);  // the gaps are 2 frames wide: one may be lost after one
  for (const int frame : {5, 9, 12, 15}) {
    const std::string prefix = "frame " + std::to_string(frame) + " ";
    std::size_t about = 0;
    for (const std::string& w : report.warnings) about += w.rfind(prefix, 0) == 0;
    EXPECT_EQ(about, 1u) << prefix;
  }
  EXPECT_EQ(report.warnings.size(), 4u);
}

}  // namespace
