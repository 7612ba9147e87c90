// ORB-SLAM2 settings: every shipped file loads into the right camera model, and malformed
// files give an orbis::Error naming the file and the key (or line), never a crash.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "orbis/camera/camera_model.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/util/error.hpp"
#include "test_data.hpp"

namespace orbis {
namespace {

std::filesystem::path settingsDir() { return test::sourceDir() / "examples/settings"; }

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class TempDir {
 public:
  TempDir() : path_(std::filesystem::temp_directory_path() / ("orbis_settings_test_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name, std::ios::binary) << text;
    return path_ / name;
  }

 private:
  std::filesystem::path path_;
};

TEST(Settings, EveryShippedFileLoads) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(settingsDir())) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const Settings s = Settings::load(entry.path());
    EXPECT_EQ(s.source, entry.path());
    EXPECT_GT(s.orb.features, 0);
    // One dispatch at the boundary; past it the camera is a concrete, compile-time type.
    std::visit(
        [](const auto& camera) {
          EXPECT_TRUE(CameraModel<std::decay_t<decltype(camera)>>);
          EXPECT_GT(camera.closeDepthThreshold(), 0.0);
        },
        s.camera);
    ++count;
  }
  EXPECT_EQ(count, 6);  // EuRoC, KITTI00-02, KITTI04-12, TUM1-3
}

TEST(Settings, TumFilesAreRgbdWithVirtualBaseline) {
  const Settings s = Settings::load(settingsDir() / "TUM1.yaml");
  ASSERT_EQ(s.sensor, SensorKind::Rgbd);
  const auto& camera = std::get<RgbdCamera<double>>(s.camera);
  EXPECT_DOUBLE_EQ(camera.pinhole.fx, 517.306408);
  EXPECT_DOUBLE_EQ(camera.pinhole.cy, 255.313989);
  EXPECT_EQ(camera.pinhole.width, 640);
  EXPECT_NEAR(camera.bf(), 40.0, 1e-12);
  EXPECT_NEAR(camera.closeDepthThreshold(), 40.0 * 40.0 / 517.306408, 1e-12);  // ThDepth * bf / fx
  EXPECT_DOUBLE_EQ(camera.depthScale, 5000.0);
  EXPECT_DOUBLE_EQ(camera.disparitySigma, 0.125);
  EXPECT_DOUBLE_EQ(s.distortion.k3, 1.163314);
  EXPECT_DOUBLE_EQ(s.distortion.p1, -0.005358);
  EXPECT_TRUE(s.rgbOrder);
  EXPECT_DOUBLE_EQ(s.fps, 30.0);
  EXPECT_EQ(s.orb.levels, 8);
  EXPECT_FLOAT_EQ(s.orb.scaleFactor, 1.2f);
  EXPECT_FALSE(s.rectification);

  const Settings mono = Settings::load(settingsDir() / "TUM1.yaml", SensorKind::Monocular);
  ASSERT_EQ(mono.sensor, SensorKind::Monocular);
  EXPECT_DOUBLE_EQ(std::get<PinholeCamera<double>>(mono.camera).fx, 517.306408);
}

// The published key list is the reader's (load() refuses to look up any other key): every key
// a shipped file sets, except ORB-SLAM2's Viewer.*, is in it, once.
TEST(Settings, KeyListCoversEveryShippedKey) {
  std::set<std::string_view> accepted;
  for (const SettingsKey& k : settingsKeys()) EXPECT_TRUE(accepted.insert(k.name).second) << k.name;
  EXPECT_TRUE(accepted.count("ORBextractor.nFeatures"));
  const std::regex topLevelKey(R"(^([A-Za-z][A-Za-z0-9_.]*):)");
  for (const auto& entry : std::filesystem::directory_iterator(settingsDir())) {
    std::istringstream lines(slurp(entry.path()));
    for (std::string line; std::getline(lines, line);) {
      std::smatch m;
      if (!std::regex_search(line, m, topLevelKey) || m[1].str().rfind("Viewer.", 0) == 0) continue;
      EXPECT_TRUE(accepted.count(m[1].str())) << entry.path() << ": " << m[1];
    }
  }
}

TEST(Settings, Tum2CorrectsTheKinectDepthScale) {
  const Settings s = Settings::load(settingsDir() / "TUM2.yaml");
  EXPECT_DOUBLE_EQ(std::get<RgbdCamera<double>>(s.camera).depthScale, 5208.0);  // as ORB-SLAM2's TUM2.yaml
}

TEST(Settings, KittiIsStereoWithThDepthThreshold) {
  const Settings s = Settings::load(settingsDir() / "KITTI04-12.yaml");
  ASSERT_EQ(s.sensor, SensorKind::Stereo);
  const auto& camera = std::get<RectifiedStereoCamera<double>>(s.camera);
  EXPECT_NEAR(camera.bf(), 379.8145, 1e-9);
  EXPECT_NEAR(camera.baseline, 379.8145 / 707.0912, 1e-12);
  EXPECT_NEAR(camera.closeDepthThreshold(), 35.0 * 379.8145 / 707.0912, 1e-9);
  EXPECT_EQ(s.orb.features, 2000);
  EXPECT_DOUBLE_EQ(s.fps, 10.0);
  EXPECT_TRUE(s.distortion.isZero());
}

TEST(Settings, EurocHasRectificationBlocks) {
  const Settings s = Settings::load(settingsDir() / "EuRoC.yaml");
  ASSERT_EQ(s.sensor, SensorKind::Stereo);
  ASSERT_TRUE(s.rectification);
  EXPECT_DOUBLE_EQ(s.rectification->left.K(0, 2), 367.215);
  EXPECT_DOUBLE_EQ(s.rectification->right.D.p2, -3.555907e-05);
  EXPECT_DOUBLE_EQ(s.rectification->right.P(0, 3), -47.90639384423901);
  const StereoRectification rect = s.stereoRectification();
  const auto& camera = std::get<RectifiedStereoCamera<double>>(s.camera);
  EXPECT_NEAR(rect.camera.bf(), camera.bf(), 1e-9);
  EXPECT_NEAR(rect.camera.pinhole.cx, camera.pinhole.cx, 1e-9);
  EXPECT_EQ(rect.leftMapX.size(), cv::Size(752, 480));
  EXPECT_THROW(Settings::load(settingsDir() / "TUM3.yaml").stereoRectification(), Error);
}

// The faults of the brief and a few more: each must name the file and the key (or the line).
class MalformedSettings : public ::testing::Test {
 protected:
  // `where` is Error::where(): "key <name>", "line <n>", or empty when only the file is known.
  void expectError(const std::string& name, const std::string& text, const std::string& where) {
    const auto path = dir_.write(name, text);
    try {
      Settings::load(path);
      ADD_FAILURE() << name << ": loaded without error";
    } catch (const Error& e) {
      std::printf("[settings] %s -> %s\n", name.c_str(), e.what());
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_EQ(e.where(), where) << e.what();
    }
  }
  void expectKeyError(const std::string& name, const std::string& text, const std::string& key) {
    expectError(name, text, "key " + key);
  }
  void expectFileError(const std::string& name, const std::string& text, const std::string& where) {
    expectError(name, text, where);
  }
  static std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
  }
  const std::string tum1_ = slurp(settingsDir() / "TUM1.yaml");
  TempDir dir_;
};

TEST_F(MalformedSettings, MissingKey) {
  expectKeyError("missing_fx.yaml", replaced(tum1_, "Camera.fx: 517.306408\n", ""), "Camera.fx");
  expectKeyError("missing_levels.yaml", replaced(tum1_, "ORBextractor.nLevels: 8", ""), "ORBextractor.nLevels");
  expectKeyError("rgbd_without_factor.yaml",
                 replaced(replaced(tum1_, "DepthMapFactor: 5000.0", ""), "System.seed: 0", "Sensor: rgbd"),
                 "DepthMapFactor");
}

TEST_F(MalformedSettings, WrongTypeOrValue) {
  expectKeyError("text_fy.yaml", replaced(tum1_, "Camera.fy: 516.469215", "Camera.fy: \"five hundred\""), "Camera.fy");
  expectKeyError("negative_fx.yaml", replaced(tum1_, "Camera.fx: 517.306408", "Camera.fx: -517.306408"),
                 "Camera.fx");
  expectKeyError("fractional_levels.yaml", replaced(tum1_, "ORBextractor.nLevels: 8", "ORBextractor.nLevels: 8.5"),
                 "ORBextractor.nLevels");
  expectKeyError("sequence_bf.yaml", replaced(tum1_, "Camera.bf: 40.0", "Camera.bf: [40.0, 1]"), "Camera.bf");
  expectKeyError("unknown_sensor.yaml", replaced(tum1_, "System.seed: 0", "Sensor: lidar"), "Sensor");
  expectKeyError("zero_right_factor.yaml",
                 replaced(tum1_, "DepthDisparitySigma: 0.125", "DepthDisparitySigma: 0.125\nORBextractor.rightFeaturesFactor: 0"),
                 "ORBextractor.rightFeaturesFactor");
  expectKeyError("zero_disparity_sigma.yaml", replaced(tum1_, "DepthDisparitySigma: 0.125", "DepthDisparitySigma: 0"),
                 "DepthDisparitySigma");
  const std::string euroc = slurp(settingsDir() / "EuRoC.yaml");
  expectKeyError("short_P.yaml", replaced(euroc, "   rows: 3\n   cols: 4\n   dt: d\n   data: [435.2046959714599, 0, 367.4517211914062, -47",
                                          "   rows: 3\n   cols: 3\n   dt: d\n   data: [435.2046959714599, 0, 367.4517211914062, -47"),
                 "RIGHT.P.data");
}

TEST_F(MalformedSettings, RightFeaturesFactorIsOptional) {
  EXPECT_EQ(Settings::load(dir_.write("plain.yaml", tum1_)).orb.rightFeaturesFactor, 1);
  const std::string wider = replaced(tum1_, "DepthDisparitySigma: 0.125", "DepthDisparitySigma: 0.125\nORBextractor.rightFeaturesFactor: 3");
  EXPECT_EQ(Settings::load(dir_.write("wider.yaml", wider)).orb.rightFeaturesFactor, 3);
}

TEST_F(MalformedSettings, TruncatedOrNotYaml) {
  // Cut at a line end: still YAML, so the first key that went missing is named.
  const auto cut = tum1_.find("Camera.k1");
  expectKeyError("truncated_at_line.yaml", tum1_.substr(0, cut), "Camera.k1");
  // Cut inside a key: the dangling word is no key, so the key it was is named missing.
  const auto mid = tum1_.find("Camera.k2") + 6;
  expectKeyError("truncated_mid_key.yaml", tum1_.substr(0, mid), "Camera.k2");
  // Text that is no YAML: the parser's error names the line.
  const auto fx = tum1_.find("Camera.fx");
  const auto line = std::count(tum1_.begin(), tum1_.begin() + static_cast<std::ptrdiff_t>(fx), '\n') + 1;
  expectFileError("unquoted_colon.yaml", replaced(tum1_, "Camera.fx: 517.306408", "Camera.fx: [517.306408: ]]"),
                  "line " + std::to_string(line));
  expectFileError("not_yaml.yaml", "\x89PNG\r\n\x1a\n binary image data", "");
  expectFileError("no_header.yaml", "Camera.fx: 500\nCamera.fy: 500\n", "");
  expectFileError("empty.yaml", "", "");
  try {
    Settings::load(std::filesystem::temp_directory_path() / "orbis_no_such_settings.yaml");
    ADD_FAILURE() << "missing file loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("orbis_no_such_settings.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace orbis
