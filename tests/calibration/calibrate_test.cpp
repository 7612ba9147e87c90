// Calibration against rendered boards with exact intrinsics: a pinhole with strong radial-
// tangential distortion and a 180-degree fisheye are recovered to 0.5% in focal length and 1 px
// in principal point; the written settings load as the camera they describe; every bad input is
// a clear error.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "error_message.hpp"
#include "orbis/calibration/calibrate.hpp"
#include "orbis/calibration/calibration_output.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/synth/calibration_views.hpp"
#include "orbis/util/error.hpp"

namespace orbis::calibration {
namespace {

namespace fs = std::filesystem;

CalibratedCamera pinholeTruth() {
  CalibratedCamera c;
  c.model = LensModel::Pinhole;
  c.width = 480, c.height = 360;
  c.fx = 380, c.fy = 378, c.cx = 242.5, c.cy = 178.0;
  c.distortion = {-0.28, 0.08, 0.0006, -0.0004, 0.0};
  return c;
}

CalibratedCamera fisheyeTruth() {
  CalibratedCamera c;
  c.model = LensModel::Fisheye;
  c.width = 480, c.height = 480;
  c.distortion = {0.01, -0.002, 0.0005, 0.0};
  // 180 degrees across the width through the centre.
  KannalaBrandtCamera<double> k;
  k.k1 = 0.01, k.k2 = -0.002, k.k3 = 0.0005;
  c.fx = c.fy = 240.0 / k.distortAngle(M_PI / 2);
  c.cx = 239.5, c.cy = 240.5;
  return c;
}

std::vector<CalibrationView> renderAndDetect(const CalibratedCamera& truth, const CalibrationPattern& pattern,
                                             int views, std::uint64_t seed, std::vector<SE3d> poses = {}) {
  synth::CalibrationViewsOptions o;
  o.pattern = pattern;
  o.camera = truth;
  o.views = views;
  o.seed = seed;
  o.supersample = 2;
  o.noiseSigma = 1.0;
  o.poses = std::move(poses);
  std::vector<CalibrationView> detected;
  int i = 0;
  for (const synth::RenderedCalibrationView& v : synth::renderCalibrationViews(o))
    detected.push_back(detectView(v.image, "view_" + std::to_string(i++), pattern));
  return detected;
}

void expectRecovered(const CalibrationResult& r, const CalibratedCamera& truth, double focalTolerance = 0.005,
                     double principalTolerance = 1.0, double pixelTolerance = 3.0) {
  std::printf("  %s: fx %.3f (true %.3f, sigma %.3f) fy %.3f (%.3f) cx %.3f (%.3f, sigma %.3f) cy %.3f (%.3f), RMS %.3f px, %d views\n",
              toString(truth.model), r.camera.fx, truth.fx, r.standardDeviations[0], r.camera.fy, truth.fy, r.camera.cx,
              truth.cx, r.standardDeviations[2], r.camera.cy, truth.cy, r.rms, r.viewsUsed);
  EXPECT_LT(std::abs(r.camera.fx / truth.fx - 1), focalTolerance);
  EXPECT_LT(std::abs(r.camera.fy / truth.fy - 1), focalTolerance);
  EXPECT_LT(std::abs(r.camera.cx - truth.cx), principalTolerance);
  EXPECT_LT(std::abs(r.camera.cy - truth.cy), principalTolerance);
  EXPECT_LT(r.rms, 0.5);
  for (double s : r.standardDeviations) EXPECT_TRUE(std::isfinite(s) && s > 0);
  // The true focal length within a few reported sigmas: the uncertainties mean something.
  EXPECT_LT(std::abs(r.camera.fx - truth.fx), 6 * r.standardDeviations[0] + 0.05);
  // The lens itself: rays of the image agree with the truth's to a fraction of a pixel.
  double worst = 0;
  for (double u = 0.1; u < 0.95; u += 0.2)
    for (double v = 0.1; v < 0.95; v += 0.2) {
      const Eigen::Vector2d px(u * truth.width, v * truth.height);
      worst = std::max(worst, (r.camera.project(truth.bearing(px)) - px).norm());
    }
  // Not a pixel: a principal point error within its sigma shifts every pixel that much.
  std::printf("  worst pixel disagreement over the image: %.3f px\n", worst);
  EXPECT_LT(worst, pixelTolerance);
}

TEST(Calibrate, PinholeWithDistortionRecovered) {
  const CalibrationPattern pattern = parsePattern("chessboard:9x6:0.03");
  const CalibratedCamera truth = pinholeTruth();
  const CalibrationResult r = calibrate(renderAndDetect(truth, pattern, 30, 3), pattern, {}, "rendered");
  expectRecovered(r, truth);
  EXPECT_EQ(r.parameterNames.size(), 9u);
}

TEST(Calibrate, FisheyeAt180DegreesRecovered) {
  const CalibrationPattern pattern = parsePattern("chessboard:8x5:0.03");
  const CalibratedCamera truth = fisheyeTruth();
  CalibrationOptions options;
  options.model = LensModel::Fisheye;
  const CalibrationResult r = calibrate(renderAndDetect(truth, pattern, 20, 5), pattern, options, "rendered");
  expectRecovered(r, truth);
  // The angle across the width (boards reached 80 degrees off axis; 90 is a short extrapolation).
  EXPECT_NEAR(r.camera.fisheye().horizontalFieldOfViewDegrees(), truth.fisheye().horizontalFieldOfViewDegrees(), 2.0);
}

TEST(Calibrate, WrittenSettingsLoadAsTheCamera) {
  const fs::path dir = fs::temp_directory_path() / "orbis_calibrate_settings";
  fs::create_directories(dir);
  const CalibratedCamera fisheye = fisheyeTruth();
  writeCalibrationSettings(dir / "fisheye.yaml", fisheye);
  const Settings s = Settings::load(dir / "fisheye.yaml");
  const auto* kb = std::get_if<KannalaBrandtCamera<double>>(&s.camera);
  ASSERT_NE(kb, nullptr);
  EXPECT_NEAR(kb->fx, fisheye.fx, 1e-6);  // written with 10 significant digits
  EXPECT_NEAR(kb->k2, fisheye.distortion[1], 1e-12);
  EXPECT_EQ(kb->width, fisheye.width);
  EXPECT_GT(kb->maxAngle, M_PI / 2);
  const CalibratedCamera pinhole = pinholeTruth();
  writeCalibrationSettings(dir / "pinhole.yaml", pinhole);
  const Settings p = Settings::load(dir / "pinhole.yaml");
  ASSERT_NE(std::get_if<PinholeCamera<double>>(&p.camera), nullptr);
  EXPECT_NEAR(p.distortion.k1, pinhole.distortion[0], 1e-12);
  EXPECT_NEAR(p.distortion.p2, pinhole.distortion[3], 1e-12);
  fs::remove_all(dir);
}

TEST(Calibrate, CharucoBoardDetectedAndCalibrated) {
  const CalibrationPattern pattern = parsePattern("charuco:7x5:0.04:0.03");
  const CalibratedCamera truth = pinholeTruth();
  const std::vector<CalibrationView> views = renderAndDetect(truth, pattern, 20, 9);
  int found = 0;
  for (const CalibrationView& v : views) found += v.detection.has_value();
  EXPECT_GE(found, 18);
  // A 7x5 ChArUco board has 24 corners against the chessboard's 54: looser bounds.
  const CalibrationResult r = calibrate(views, pattern, {}, "rendered charuco");
  expectRecovered(r, truth, 0.01, 3.0, 6.0);
}

TEST(Calibrate, PatternSpecErrors) {
  EXPECT_THROW(parsePattern("chessboard:9x6"), Error);
  EXPECT_THROW(parsePattern("chessboard:9by6:0.02"), Error);
  EXPECT_THROW(parsePattern("chessboard:1x6:0.02"), Error);
  EXPECT_THROW(parsePattern("chessboard:9x6:-1"), Error);
  EXPECT_THROW(parsePattern("charuco:7x5:0.04:0.05"), Error);  // marker larger than the square
  EXPECT_THROW(parsePattern("charuco:20x20:0.04:0.03:DICT_4X4_50"), Error);  // 200 markers, 50 codes
  EXPECT_THROW(parsePattern("circles:4x11:0.02"), Error);
  const CalibrationPattern p = parsePattern("charuco:7x5:0.04:0.03:DICT_5X5_100");
  EXPECT_EQ(p.cornerCount(), 24);
  EXPECT_EQ(parsePattern(p.describe()).dictionary, "DICT_5X5_100");
}

TEST(Calibrate, BadInputsSayWhatToDo) {
  const CalibrationPattern pattern = parsePattern("chessboard:9x6:0.03");
  const CalibratedCamera truth = pinholeTruth();
  // No pattern: blank images, or the wrong size given.
  std::vector<CalibrationView> blank(5);
  for (std::size_t i = 0; i < blank.size(); ++i) blank[i] = detectView(cv::Mat(360, 480, CV_8UC1, cv::Scalar(128)), "blank", pattern);
  const std::string none = messageOf([&] { calibrate(blank, pattern, {}, "blank/"); });
  std::printf("  no pattern: %s\n", none.c_str());
  EXPECT_NE(none.find("no image shows the pattern"), std::string::npos);
  // Too few views.
  const std::string few = messageOf([&] { calibrate(renderAndDetect(truth, pattern, 3, 4), pattern, {}, "three/"); });
  std::printf("  too few: %s\n", few.c_str());
  EXPECT_NE(few.find("at least 6"), std::string::npos);
}

// The fitted board poses of such a set come out tilted (the fit trades focal length for tilt), so
// the check must not rely on them: calibrate() measures the depth spread from the homographies.
TEST(Calibrate, UntiltedViewsAreRefusedAsDegenerate) {
  const CalibrationPattern pattern = parsePattern("chessboard:9x6:0.03");
  const CalibratedCamera truth = pinholeTruth();
  // Degenerate: the board always square to an undistorted camera at one distance; only its place
  // changes, which leaves the focal length and the distance interchangeable.
  CalibratedCamera ideal = truth;
  ideal.distortion.assign(5, 0.0);
  std::vector<SE3d> flat;
  for (int i = 0; i < 8; ++i)
    flat.emplace_back(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.2 + 0.02 * (i % 4), -0.12 + 0.03 * (i / 4), 0.55));
  const std::string degenerate = messageOf([&] { calibrate(renderAndDetect(ideal, pattern, 0, 4, flat), pattern, {}, "flat/"); });
  std::printf("  degenerate: %s\n", degenerate.c_str());
  EXPECT_TRUE(degenerate.find("degenerate") != std::string::npos) << degenerate;
  EXPECT_TRUE(degenerate.find("Tilt the board by 20-45 degrees") != std::string::npos) << degenerate;
}

TEST(Calibrate, DuplicateAndOutlierViewsNamed) {
  const CalibrationPattern pattern = parsePattern("chessboard:9x6:0.03");
  const CalibratedCamera truth = pinholeTruth();
  std::vector<CalibrationView> views = renderAndDetect(truth, pattern, 12, 6);
  views.push_back(views[2]);
  views.back().name = "copy_of_2";
  // One view whose corners are shifted by 4 px: a bad detection.
  CalibrationView shifted = views[5];
  shifted.name = "shifted";
  for (cv::Point2f& p : shifted.detection->corners) p.x += (&p - shifted.detection->corners.data()) % 2 ? 4.f : -4.f;
  views[5] = shifted;
  const CalibrationResult r = calibrate(views, pattern, {}, "rendered");
  EXPECT_EQ(r.views.back().rejected, "duplicate of view_2");
  EXPECT_TRUE(r.views[5].outlier);
  EXPECT_FALSE(r.views[5].used);
  EXPECT_LT(r.rms, 0.5);
}

}  // namespace
}  // namespace orbis::calibration
