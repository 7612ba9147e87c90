// Radial-tangential distortion: forward model against OpenCV's projectPoints, the Jacobian
// against numeric differentiation, and undistortion of keypoints against a known distortion.
#include <algorithm>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "orbis/camera/distortion.hpp"

namespace orbis {
namespace {

// EuRoC cam0 (strong barrel distortion) and TUM freiburg1 (all five coefficients).
const PinholeCamera<double> kEurocCam0{458.654, 457.296, 367.215, 248.375, 752, 480};
const RadTanDistortion<double> kEurocLens{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
const PinholeCamera<double> kTum1{517.306408, 516.469215, 318.643040, 255.313989, 640, 480};
const RadTanDistortion<double> kTum1Lens{0.262383, -0.953104, -0.005358, 0.002628, 1.163314};

std::vector<Eigen::Vector2d> pixelGrid(const PinholeCamera<double>& camera, int step) {
  std::vector<Eigen::Vector2d> pixels;
  for (int v = 0; v <= camera.height; v += step)
    for (int u = 0; u <= camera.width; u += step) pixels.emplace_back(u, v);
  return pixels;
}

cv::Mat cameraMatrix(const PinholeCamera<double>& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}
cv::Mat coefficients(const RadTanDistortion<double>& d) {
  return (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
}

TEST(RadTanDistortion, ForwardModelMatchesOpenCv) {
  for (const auto& [camera, lens] : {std::pair{kEurocCam0, kEurocLens}, std::pair{kTum1, kTum1Lens}}) {
    std::vector<cv::Point3d> rays;
    std::vector<Eigen::Vector2d> ideal = pixelGrid(camera, 40);
    for (const auto& px : ideal) {
      const Eigen::Vector3d ray = camera.normalizedRay(px);
      rays.emplace_back(ray.x(), ray.y(), 1.0);
    }
    std::vector<cv::Point2d> projected;
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cameraMatrix(camera), coefficients(lens),
                      projected);
    double maxDiff = 0;
    for (std::size_t i = 0; i < ideal.size(); ++i) {
      const Eigen::Vector2d ours = distortPixel(camera, lens, ideal[i]);
      maxDiff = std::max(maxDiff, (ours - Eigen::Vector2d(projected[i].x, projected[i].y)).norm());
    }
    EXPECT_LT(maxDiff, 1e-9);
  }
}

TEST(RadTanDistortion, JacobianMatchesNumericDifferentiation) {
  double maxDiff = 0;
  for (const auto& lens : {kEurocLens, kTum1Lens}) {
    for (double x = -0.8; x <= 0.8; x += 0.1) {
      for (double y = -0.6; y <= 0.6; y += 0.1) {
        const Eigen::Vector2d xn(x, y);
        Eigen::Matrix2d numeric;
        const double h = 1e-7;
        for (int k = 0; k < 2; ++k) {
          Eigen::Vector2d plus = xn, minus = xn;
          plus[k] += h;
          minus[k] -= h;
          numeric.col(k) = (lens.distort(plus) - lens.distort(minus)) / (2 * h);
        }
        maxDiff = std::max(maxDiff, (lens.distortJacobian(xn) - numeric).cwiseAbs().maxCoeff());
      }
    }
  }
  std::printf("[jacobian] RadTanDistortion distortJacobian max|diff| = %.3g\n", maxDiff);
  EXPECT_LT(maxDiff, 1e-7);
}

// Known distortion: distort an ideal grid with the forward model, undistort, get the grid back.
TEST(RadTanDistortion, UndistortInvertsKnownDistortion) {
  for (const auto& [camera, lens] : {std::pair{kEurocCam0, kEurocLens}, std::pair{kTum1, kTum1Lens}}) {
    double maxError = 0;
    for (const auto& ideal : pixelGrid(camera, 16)) {
      const Eigen::Vector2d distorted = distortPixel(camera, lens, ideal);
      maxError = std::max(maxError, (undistortPixel(camera, lens, distorted) - ideal).norm());
    }
    std::printf("[undistort] fx %.1f: max round-trip error %.3g px\n", camera.fx, maxError);
    EXPECT_LT(maxError, 1e-6);
  }
}

TEST(RadTanDistortion, AgreesWithOpenCvUndistortPoints) {
  std::vector<cv::Point2d> distorted;
  for (const auto& px : pixelGrid(kEurocCam0, 50)) distorted.emplace_back(px.x(), px.y());
  std::vector<cv::Point2d> reference;
  cv::undistortPoints(distorted, reference, cameraMatrix(kEurocCam0), coefficients(kEurocLens), cv::noArray(),
                      cameraMatrix(kEurocCam0), cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  double maxDiff = 0;
  for (std::size_t i = 0; i < distorted.size(); ++i) {
    const Eigen::Vector2d ours = undistortPixel(kEurocCam0, kEurocLens, Eigen::Vector2d(distorted[i].x, distorted[i].y));
    maxDiff = std::max(maxDiff, (ours - Eigen::Vector2d(reference[i].x, reference[i].y)).norm());
  }
  EXPECT_LT(maxDiff, 1e-4);
}

struct UvKeypoint {
  float u, v;
  int octave;
};

TEST(UndistortPoints, KeypointsOfEitherShape) {
  const Eigen::Vector2d ideal(100.0, 60.0);
  const Eigen::Vector2d distorted = distortPixel(kEurocCam0, kEurocLens, ideal);
  const std::vector<UvKeypoint> uv{{float(distorted.x()), float(distorted.y()), 3}};
  const auto undistortedUv = undistortPoints(uv, kEurocCam0, kEurocLens);
  ASSERT_EQ(undistortedUv.size(), 1u);
  EXPECT_NEAR(undistortedUv[0].u, ideal.x(), 1e-3);
  EXPECT_NEAR(undistortedUv[0].v, ideal.y(), 1e-3);
  EXPECT_EQ(undistortedUv[0].octave, 3);

  const std::vector<cv::KeyPoint> cvKeys{cv::KeyPoint(float(distorted.x()), float(distorted.y()), 31.f)};
  const auto undistortedCv = undistortPoints(cvKeys, kEurocCam0, kEurocLens);
  EXPECT_NEAR(undistortedCv[0].pt.x, ideal.x(), 1e-3);
  EXPECT_NEAR(undistortedCv[0].pt.y, ideal.y(), 1e-3);
  EXPECT_FLOAT_EQ(undistortedCv[0].size, 31.f);

  // An ideal lens leaves keypoints untouched.
  EXPECT_EQ(undistortPoints(uv, kEurocCam0, RadTanDistortion<double>{})[0].u, uv[0].u);
}

}  // namespace
}  // namespace orbis
