// Stereo rig calibration against rendered boards seen by two cameras with known intrinsics and
// extrinsics: both cameras within 0.5% in focal length and 1 px in principal point, the baseline
// within 1% and a few reported sigmas, and the written settings load as the rectified stereo camera
// with rectification blocks that put a scene point on one row in both images.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "error_message.hpp"
#include "orbis/calibration/calibration_output.hpp"
#include "orbis/calibration/stereo_calibrate.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/synth/calibration_views.hpp"
#include "orbis/util/error.hpp"

namespace orbis::calibration {
namespace {

namespace fs = std::filesystem;

struct Rig {
  CalibratedCamera left, right;
  SE3d rightFromLeft;
};

SE3d rigPose(double baseline) {
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.012, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(-0.008, Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix();
  // The right camera 'baseline' to the right of the left one, slightly turned: x_right = R x_left + t.
  return SE3d(turn, -(turn * Eigen::Vector3d(baseline, 0.003, -0.002)));
}

Rig pinholeRig() {
  Rig rig;
  rig.left.model = rig.right.model = LensModel::Pinhole;
  rig.left.width = rig.right.width = 480;
  rig.left.height = rig.right.height = 360;
  rig.left.fx = 380, rig.left.fy = 378, rig.left.cx = 242.5, rig.left.cy = 178.0;
  rig.left.distortion = {-0.28, 0.08, 0.0006, -0.0004, 0.0};
  rig.right.fx = 384, rig.right.fy = 383, rig.right.cx = 236.0, rig.right.cy = 181.5;
  rig.right.distortion = {-0.26, 0.07, -0.0003, 0.0005, 0.0};
  rig.rightFromLeft = rigPose(0.12);
  return rig;
}

Rig fisheyeRig() {
  Rig rig;
  rig.left.model = rig.right.model = LensModel::Fisheye;
  rig.left.width = rig.right.width = 400;
  rig.left.height = rig.right.height = 400;
  KannalaBrandtCamera<double> k;
  k.k1 = 0.01, k.k2 = -0.002, k.k3 = 0.0005;
  // 190 degrees across the width through the centre.
  rig.left.fx = rig.left.fy = 200.0 / k.distortAngle(95.0 * M_PI / 180.0);
  rig.left.cx = 199.5, rig.left.cy = 200.5;
  rig.left.distortion = {0.01, -0.002, 0.0005, 0.0};
  rig.right = rig.left;
  rig.right.fx *= 1.01, rig.right.fy *= 1.01, rig.right.cx = 202.0, rig.right.cy = 198.0;
  rig.right.distortion = {0.012, -0.002, 0.0004, 0.0};
  rig.rightFromLeft = rigPose(0.10);
  return rig;
}

synth::CalibrationViewsOptions viewOptions(const Rig& rig, const CalibrationPattern& pattern, int views, std::uint64_t seed) {
  synth::CalibrationViewsOptions o;
  o.pattern = pattern;
  o.camera = rig.left;
  o.rightCamera = rig.right;
  o.rightFromLeft = rig.rightFromLeft;
  o.views = views;
  o.seed = seed;
  o.supersample = 2;
  o.noiseSigma = 1.0;
  return o;
}

void detect(const synth::CalibrationViewsOptions& o, std::vector<CalibrationView>& left, std::vector<CalibrationView>& right) {
  int i = 0;
  for (const synth::RenderedCalibrationView& v : synth::renderCalibrationViews(o)) {
    left.push_back(detectView(v.image, "left_" + std::to_string(i), o.pattern));
    right.push_back(detectView(v.right, "right_" + std::to_string(i++), o.pattern));
  }
}

void expectCamera(const CalibratedCamera& estimate, const CalibratedCamera& truth, const char* side) {
  std::printf("  %s: fx %.3f (true %.3f) fy %.3f (%.3f) cx %.3f (%.3f) cy %.3f (%.3f)\n", side, estimate.fx, truth.fx,
              estimate.fy, truth.fy, estimate.cx, truth.cx, estimate.cy, truth.cy);
  EXPECT_LT(std::abs(estimate.fx / truth.fx - 1), 0.005) << side;
  EXPECT_LT(std::abs(estimate.fy / truth.fy - 1), 0.005) << side;
  EXPECT_LT(std::abs(estimate.cx - truth.cx), 1.0) << side;
  EXPECT_LT(std::abs(estimate.cy - truth.cy), 1.0) << side;
}

void expectRig(const StereoCalibrationResult& r, const Rig& truth) {
  expectCamera(r.left.camera, truth.left, "left");
  expectCamera(r.right.camera, truth.right, "right");
  const double baseline = truth.rightFromLeft.translation().norm();
  const double turn = Eigen::AngleAxisd(r.rightFromLeft.rotationMatrix() * truth.rightFromLeft.rotationMatrix().transpose()).angle();
  std::printf("  baseline %.5f m +- %.5f (true %.5f), rotation error %.4f deg, stereo RMS %.3f px, %d pairs\n", r.baseline,
              r.baselineSigma, baseline, turn * 180 / M_PI, r.rms, r.pairsUsed);
  EXPECT_LT(std::abs(r.baseline / baseline - 1), 0.01);
  EXPECT_GT(r.baselineSigma, 0);
  EXPECT_LT(r.baselineSigma, 0.01 * baseline);
  EXPECT_LT(turn, 0.2 * M_PI / 180);
  EXPECT_LT(r.rms, 0.5);
  EXPECT_NEAR(r.rectification.camera.baseline, baseline, 0.01 * baseline);
}

// The written file loads as the rectified stereo camera, and its blocks rectify a scene point
// seen raw by both cameras onto one row, at the disparity bf / Z.
void expectSettingsRectify(const StereoCalibrationResult& r, const Rig& truth, const std::string& name) {
  const fs::path file = fs::temp_directory_path() / ("orbis_stereo_" + name + ".yaml");
  writeStereoCalibrationSettings(file, r);
  const Settings s = Settings::load(file);
  const auto* stereo = std::get_if<RectifiedStereoCamera<double>>(&s.camera);
  ASSERT_NE(stereo, nullptr);
  EXPECT_EQ(s.sensor, SensorKind::Stereo);
  EXPECT_NEAR(stereo->baseline, r.rectification.camera.baseline, 1e-6);
  const StereoRectification loaded = s.stereoRectification();
  EXPECT_EQ(loaded.left.fisheye.has_value(), truth.left.model == LensModel::Fisheye);
  double worstRow = 0, worstDisparity = 0;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-0.5, 0.1, 1.5), Eigen::Vector3d(0.0, 0.3, 3.0)}) {
    const Eigen::Vector2d l = loaded.rectifyLeftPixel(truth.left.project(p));
    const Eigen::Vector2d rr = loaded.rectifyRightPixel(truth.right.project(truth.rightFromLeft * p));
    worstRow = std::max(worstRow, std::abs(l.y() - rr.y()));
    // Depth in the rectified left camera: the rectifying rotation turns the raw left camera.
    const double depth = (loaded.left.R * p).z();
    worstDisparity = std::max(worstDisparity, std::abs((l.x() - rr.x()) - stereo->pinhole.fx * stereo->baseline / depth));
  }
  std::printf("  %s settings: rows differ by %.3f px, disparity off by %.3f px at most\n", name.c_str(), worstRow, worstDisparity);
  EXPECT_LT(worstRow, 0.5);
  EXPECT_LT(worstDisparity, 0.5);
  fs::remove(file);
}

TEST(StereoCalibrate, PinholeRigWithDistortionRecovered) {
  const CalibrationPattern pattern = parsePattern("chessboard:9x6:0.03");
  const Rig truth = pinholeRig();
  std::vector<CalibrationView> left, right;
  detect(viewOptions(truth, pattern, 20, 21), left, right);
  const StereoCalibrationResult r = calibrateStereo(left, right, pattern, {}, "rendered rig");
  expectRig(r, truth);
  expectSettingsRectify(r, truth, "pinhole");
}

TEST(StereoCalibrate, FisheyeRigAt190DegreesRecovered) {
  const CalibrationPattern pattern = parsePattern("chessboard:8x5:0.03");
  const Rig truth = fisheyeRig();
  std::vector<CalibrationView> left, right;
  detect(viewOptions(truth, pattern, 20, 5), left, right);
  CalibrationOptions options;
  options.model = LensModel::Fisheye;
  const StereoCalibrationResult r = calibrateStereo(left, right, pattern, options, "rendered fisheye rig");
  expectRig(r, truth);
  expectSettingsRectify(r, truth, "fisheye");
}

TEST(StereoCalibrate, MismatchedOrSwappedPairsSayWhatToDo) {
  const CalibrationPattern pattern = parsePattern("chessboard:9x6:0.03");
  const Rig truth = pinholeRig();
  std::vector<CalibrationView> left, right;
  detect(viewOptions(truth, pattern, 8, 23), left, right);
  std::vector<CalibrationView> shorter(right.begin(), right.end() - 1);
  const std::string counts = messageOf([&] { calibrateStereo(left, shorter, pattern, {}, "rig/"); });
  std::printf("  counts: %s\n", counts.c_str());
  EXPECT_NE(counts.find("gave 8 views but the right 7"), std::string::npos) << counts;
  const std::string swapped = messageOf([&] { calibrateStereo(right, left, pattern, {}, "rig/"); });
  std::printf("  swapped: %s\n", swapped.c_str());
  EXPECT_NE(swapped.find("swap the two streams"), std::string::npos) << swapped;
}

}  // namespace
}  // namespace orbis::calibration
