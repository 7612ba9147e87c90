// EuRoC calibration reader and stereo rectification, checked on the real images: after
// rectification ORB matches between left and right must lie on the same row.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include "orbis/camera/euroc_calibration.hpp"
#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/io/settings.hpp"
#include "orbis/util/error.hpp"
#include "test_data.hpp"

namespace orbis {
namespace {

constexpr const char* kEuroc = "euroc_V1_01_easy_95";

std::vector<std::string> imageNames(const std::filesystem::path& camDir) {
  std::ifstream csv(camDir / "data.csv");
  std::vector<std::string> names;
  for (std::string line; std::getline(csv, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    std::string name = line.substr(comma + 1);
    while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.pop_back();
    names.push_back(name);
  }
  return names;
}

double median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// |v_left - v_right| of cross-checked ORB matches with a small Hamming distance and a plausible
// disparity (no filter on rows, which would bias the measurement). Positions are refined to
// sub-pixel with cornerSubPix so that the median is not quantised to whole pixels.
std::vector<double> rowDifferences(const cv::Mat& left, const cv::Mat& right) {
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1500);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  orb->detectAndCompute(left, cv::noArray(), kl, dl);
  orb->detectAndCompute(right, cv::noArray(), kr, dr);
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(cv::NORM_HAMMING, /*crossCheck=*/true).match(dl, dr, matches);
  std::vector<cv::Point2f> pl, pr;
  for (const cv::DMatch& m : matches) {
    const cv::Point2f a = kl[m.queryIdx].pt, b = kr[m.trainIdx].pt;
    if (m.distance > 40 || kl[m.queryIdx].octave != 0 || kr[m.trainIdx].octave != 0) continue;
    if (a.x - b.x < -2 || a.x - b.x > 120) continue;
    pl.push_back(a);
    pr.push_back(b);
  }
  if (pl.empty()) return {};
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::cornerSubPix(left, pl, cv::Size(4, 4), cv::Size(-1, -1), criteria);
  cv::cornerSubPix(right, pr, cv::Size(4, 4), cv::Size(-1, -1), criteria);
  std::vector<double> dv;
  for (std::size_t i = 0; i < pl.size(); ++i) dv.push_back(std::abs(pl[i].y - pr[i].y));
  return dv;
}

TEST(EurocCalibration, ReadsSensorYaml) {
  ORBIS_REQUIRE_DATASET(root, kEuroc);
  const CameraCalibration cam0 = readEurocCalibration(root / "mav0/cam0/sensor.yaml");
  EXPECT_DOUBLE_EQ(cam0.intrinsics.fx, 458.654);
  EXPECT_DOUBLE_EQ(cam0.intrinsics.cy, 248.375);
  EXPECT_EQ(cam0.intrinsics.width, 752);
  EXPECT_EQ(cam0.intrinsics.height, 480);
  EXPECT_DOUBLE_EQ(cam0.distortion.k1, -0.28340811);
  EXPECT_DOUBLE_EQ(cam0.distortion.p2, 1.76187114e-05);
  EXPECT_DOUBLE_EQ(cam0.distortion.k3, 0.0);
  EXPECT_DOUBLE_EQ(cam0.bodyFromCamera(1, 3), -0.064676986768);
  EXPECT_DOUBLE_EQ(cam0.bodyFromCamera(3, 3), 1.0);
}

TEST(EurocCalibration, MalformedFilesNameFileAndKey) {
  const auto dir = std::filesystem::temp_directory_path() / ("orbis_camera_euroc_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string good =
      "%YAML:1.0\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"
      "resolution: [752, 480]\ncamera_model: pinhole\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
      "distortion_model: radial-tangential\ndistortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n";
  auto expectError = [&](const std::string& name, std::string text, const std::string& key) {
    const auto path = dir / name;
    std::ofstream(path) << text;
    try {
      readEurocCalibration(path);
      ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_EQ(e.where(), "key " + key) << e.what();
    }
  };
  ASSERT_NO_THROW(readEurocCalibration([&] {
    std::ofstream(dir / "good.yaml") << good;
    return dir / "good.yaml";
  }()));
  auto replace = [&](std::string from, std::string to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  expectError("missing.yaml", replace("intrinsics: [458.6, 457.3, 367.2, 248.4]\n", ""), "intrinsics");
  expectError("short.yaml", replace("[458.6, 457.3, 367.2, 248.4]", "[458.6, 457.3, 367.2]"), "intrinsics");
  expectError("model.yaml", replace("radial-tangential", "omnidirectional"), "distortion_model");
  // Kalibr's equidistant model is the Kannala-Brandt fisheye: four coefficients, no more.
  expectError("fisheye5.yaml", replace("distortion_model: radial-tangential\ndistortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]",
                                       "distortion_model: equidistant\ndistortion_coefficients: [0.01, 0.0, 0.0, 0.0, 0.1]"),
              "distortion_coefficients");
  {
    std::ofstream(dir / "fisheye.yaml") << replace("distortion_model: radial-tangential", "distortion_model: equidistant");
    const CameraCalibration fisheye = readEurocCalibration(dir / "fisheye.yaml");
    ASSERT_TRUE(fisheye.fisheye.has_value());
    EXPECT_DOUBLE_EQ((*fisheye.fisheye)[0], -0.28);
    EXPECT_TRUE(fisheye.distortion.isZero());
  }
  expectError("pose.yaml", replace("data: [1, 0,", "data: [2, 0,"), "T_BS");
  std::filesystem::remove_all(dir);
}

struct RowAlignment {
  double medianRectified = NAN, medianRaw = NAN;
  std::size_t rectifiedMatches = 0, rawMatches = 0;
};

// Every 20th of the 95 pairs, matched before and after rectification.
RowAlignment measureRowAlignment(const std::filesystem::path& root, const StereoRectification& rect) {
  const auto leftNames = imageNames(root / "mav0/cam0");
  const auto rightNames = imageNames(root / "mav0/cam1");
  EXPECT_EQ(leftNames.size(), rightNames.size());
  EXPECT_GE(leftNames.size(), 80u);
  std::vector<double> rectified, raw;
  for (std::size_t i = 0; i < std::min(leftNames.size(), rightNames.size()); i += 20) {
    const cv::Mat left = cv::imread((root / "mav0/cam0/data" / leftNames[i]).string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat right = cv::imread((root / "mav0/cam1/data" / rightNames[i]).string(), cv::IMREAD_GRAYSCALE);
    EXPECT_FALSE(left.empty() || right.empty()) << leftNames[i];
    if (left.empty() || right.empty()) continue;
    const auto images = rect.rectify(left, right);
    EXPECT_EQ(images.left.type(), CV_8UC1);
    const auto dv = rowDifferences(images.left, images.right);
    rectified.insert(rectified.end(), dv.begin(), dv.end());
    const auto dvRaw = rowDifferences(left, right);
    raw.insert(raw.end(), dvRaw.begin(), dvRaw.end());
  }
  return {median(rectified), median(raw), rectified.size(), raw.size()};
}

TEST(StereoRectification, EurocRowsAlignAfterRectification) {
  ORBIS_REQUIRE_DATASET(root, kEuroc);
  const CameraCalibration cam0 = readEurocCalibration(root / "mav0/cam0/sensor.yaml");
  const CameraCalibration cam1 = readEurocCalibration(root / "mav0/cam1/sensor.yaml");
  const StereoRectification rect = rectifyStereo(cam0, cam1);
  const auto& pin = rect.camera.pinhole;
  std::printf("[rectify] EuRoC from sensor.yaml: fx %.4f fy %.4f cx %.4f cy %.4f baseline %.5f m bf %.4f\n", pin.fx,
              pin.fy, pin.cx, pin.cy, rect.camera.baseline, rect.camera.bf());
  // The baseline is the distance between the two camera centres of T_BS (rectification rotates, never moves them).
  EXPECT_NEAR(rect.camera.baseline, (cam0.bodyFromCamera.col(3) - cam1.bodyFromCamera.col(3)).norm(), 1e-9);
  EXPECT_EQ(pin.width, 752);
  EXPECT_EQ(rect.leftMapX.size(), cv::Size(752, 480));

  const RowAlignment rows = measureRowAlignment(root, rect);
  std::printf("[rectify] EuRoC V1_01 ORB matches (sensor.yaml): median |v_left - v_right| = %.3f px rectified "
              "(%zu matches), %.3f px raw (%zu matches)\n",
              rows.medianRectified, rows.rectifiedMatches, rows.medianRaw, rows.rawMatches);
  EXPECT_GE(rows.rectifiedMatches, 100u);
  EXPECT_LT(rows.medianRectified, 0.5);
}

// ORB-SLAM2's published LEFT./RIGHT. blocks, read through the settings file we ship.
TEST(StereoRectification, EurocRowsAlignWithOrbSlam2Blocks) {
  ORBIS_REQUIRE_DATASET(root, kEuroc);
  const Settings settings = Settings::load(test::sourceDir() / "examples/settings/EuRoC.yaml");
  const StereoRectification rect = settings.stereoRectification();
  EXPECT_NEAR(rect.camera.bf(), 47.90639384423901, 1e-9);
  const RowAlignment rows = measureRowAlignment(root, rect);
  std::printf("[rectify] EuRoC V1_01 ORB matches (EuRoC.yaml blocks): median |v_left - v_right| = %.3f px "
              "rectified (%zu matches)\n",
              rows.medianRectified, rows.rectifiedMatches);
  EXPECT_GE(rows.rectifiedMatches, 100u);
  EXPECT_LT(rows.medianRectified, 0.5);
}

// A raw pixel mapped through rectifyLeftPixel must land where the remap table points back to it.
TEST(StereoRectification, PixelMappingAgreesWithRemapTables) {
  ORBIS_REQUIRE_DATASET(root, kEuroc);
  const StereoRectification rect = rectifyStereo(readEurocCalibration(root / "mav0/cam0/sensor.yaml"),
                                                 readEurocCalibration(root / "mav0/cam1/sensor.yaml"));
  double maxError = 0;
  for (int v = 40; v < 480; v += 80) {
    for (int u = 40; u < 752; u += 80) {
      for (int side = 0; side < 2; ++side) {
        const cv::Mat& mx = side == 0 ? rect.leftMapX : rect.rightMapX;
        const cv::Mat& my = side == 0 ? rect.leftMapY : rect.rightMapY;
        const Eigen::Vector2d rawPixel(mx.at<float>(v, u), my.at<float>(v, u));
        const Eigen::Vector2d back = side == 0 ? rect.rectifyLeftPixel(rawPixel) : rect.rectifyRightPixel(rawPixel);
        maxError = std::max(maxError, (back - Eigen::Vector2d(u, v)).norm());
      }
    }
  }
  EXPECT_LT(maxError, 1e-3);
}

TEST(StereoRectification, RejectsInconsistentPairs) {
  CameraCalibration left;
  left.intrinsics = {450, 450, 376, 240, 752, 480};
  CameraCalibration right = left;
  right.bodyFromCamera(0, 3) = 0.11;  // right camera 11 cm along +x: a valid pair
  EXPECT_NEAR(rectifyStereo(left, right).camera.baseline, 0.11, 1e-9);
  CameraCalibration swapped = left;
  swapped.bodyFromCamera(0, 3) = -0.11;
  EXPECT_THROW(rectifyStereo(left, swapped), Error);
  CameraCalibration smaller = right;
  smaller.intrinsics.width = 640;
  EXPECT_THROW(rectifyStereo(left, smaller), Error);
}

}  // namespace
}  // namespace orbis

namespace orbis {
namespace {

// A fisheye pair (Kannala-Brandt, 20 cm apart, the right one turned by 2 degrees) rectified to a
// pinhole pair: a scene point lands on one row in both rectified images, at disparity bf / Z.
TEST(Rectification, FisheyePairRectifiedToPinholes) {
  CameraCalibration left, right;
  left.intrinsics = right.intrinsics = {190.0, 190.0, 320.0, 240.0, 640, 480};
  left.fisheye = right.fisheye = std::array<double, 4>{0.01, -0.002, 0.0005, 0.0};
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  right.bodyFromCamera.topLeftCorner<3, 3>() = turn;
  right.bodyFromCamera(0, 3) = 0.2;
  const StereoRectification r = rectifyStereo(left, right);
  EXPECT_NEAR(r.camera.baseline, 0.2, 1e-9);
  ASSERT_FALSE(r.leftMapX.empty());
  KannalaBrandtCamera<double> lens;
  lens.fx = lens.fy = 190.0, lens.cx = 320.0, lens.cy = 240.0, lens.k1 = 0.01, lens.k2 = -0.002, lens.k3 = 0.0005;
  int checked = 0;
  for (double x : {-0.8, 0.0, 0.9})
    for (double y : {-0.5, 0.3})
      for (double z : {2.0, 5.0}) {
        const Eigen::Vector3d inLeft(x, y, z);
        const Eigen::Vector3d inRight = turn.transpose() * (inLeft - Eigen::Vector3d(0.2, 0, 0));
        const Eigen::Vector2d l = r.rectifyLeftPixel(lens.project(inLeft));
        const Eigen::Vector2d rr = r.rectifyRightPixel(lens.project(inRight));
        EXPECT_NEAR(l.y(), rr.y(), 1e-6);
        // Depth in the rectified left frame: the rectifying rotation turns the camera slightly.
        const double depth = (r.left.R * inLeft).z();
        EXPECT_NEAR(l.x() - rr.x(), r.camera.bf() / depth, 1e-6);
        ++checked;
      }
  EXPECT_EQ(checked, 12);
}

}  // namespace
}  // namespace orbis
