// The Kannala–Brandt model past what the generic harness covers: rays at and beyond 90° off axis
// (behind the image plane), the unprojection Jacobian, and agreement with OpenCV's fisheye model.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "orbis/camera/kannala_brandt.hpp"

namespace orbis {
namespace {

KannalaBrandtCamera<double> wideFisheye() {
  KannalaBrandtCamera<double> c;
  c.fx = 190.98, c.fy = 190.97, c.cx = 318.4, c.cy = 241.7;
  c.k1 = 0.0034, c.k2 = 0.0007, c.k3 = -0.0020, c.k4 = 0.0003;
  c.width = 640, c.height = 480;
  return c;
}

// Unit rays up to `maxAngle` off axis, in every azimuth.
std::vector<Eigen::Vector3d> raysUpTo(double maxAngle, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0.01, maxAngle), azimuth(-std::numbers::pi, std::numbers::pi),
      range(0.2, 20.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double t = angle(rng), a = azimuth(rng);
    points.push_back(range(rng) * Eigen::Vector3d(std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)));
  }
  return points;
}

TEST(KannalaBrandt, RaysBeyondNinetyDegreesRoundTrip) {
  const auto camera = wideFisheye();
  int behind = 0;
  for (const Eigen::Vector3d& p : raysUpTo(100.0 * std::numbers::pi / 180.0, 500, 3)) {
    ASSERT_TRUE(camera.inFront(p)) << p.transpose();
    const Eigen::Vector2d px = camera.project(p);
    const Eigen::Vector3d b = camera.bearing(px);
    EXPECT_LT((b - p.normalized()).norm(), 1e-10) << p.transpose();
    EXPECT_LT((camera.unprojectRange(px, p.norm()) - p).norm(), 1e-9 * p.norm());
    if (std::abs(p.z()) > 1e-3 * p.norm()) EXPECT_LT((camera.unproject(px, p.z()) - p).norm(), 1e-8 * p.norm());
    behind += p.z() < 0;
  }
  EXPECT_GT(behind, 20);  // the set does reach behind the image plane
  // 90° off axis lands on a finite pixel, further out than any ray in front of the plane.
  const Eigen::Vector2d side = camera.project(Eigen::Vector3d(1, 0, 0));
  EXPECT_NEAR(side.x() - camera.cx, camera.fx * camera.distortAngle(std::numbers::pi / 2), 1e-9);
  EXPECT_FALSE(camera.inFront(Eigen::Vector3d(1e-6, 0, -1)));
  EXPECT_FALSE(camera.inFront(Eigen::Vector3d::Zero()));
}

TEST(KannalaBrandt, JacobiansMatchNumericBeyondNinetyDegrees) {
  const auto camera = wideFisheye();
  double worstProject = 0, worstUnproject = 0;
  for (const Eigen::Vector3d& p : raysUpTo(100.0 * std::numbers::pi / 180.0, 300, 5)) {
    Eigen::Matrix<double, 2, 3> numeric;
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6 * p.norm();
      Eigen::Vector3d plus = p, minus = p;
      plus[k] += h;
      minus[k] -= h;
      numeric.col(k) = (camera.project(plus) - camera.project(minus)) / (2 * h);
    }
    worstProject = std::max(worstProject, (camera.projectJacobian(p) - numeric).cwiseAbs().maxCoeff() /
                                              std::max(1.0, numeric.cwiseAbs().maxCoeff()));
    const Eigen::Vector2d px = camera.project(p);
    Eigen::Matrix<double, 3, 2> numericUnproject;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d plus = px, minus = px;
      plus[k] += 1e-4;
      minus[k] -= 1e-4;
      numericUnproject.col(k) = (camera.bearing(plus) - camera.bearing(minus)) / 2e-4;
    }
    worstUnproject = std::max(worstUnproject, (camera.unprojectJacobian(px) - numericUnproject).cwiseAbs().maxCoeff() /
                                                  numericUnproject.cwiseAbs().maxCoeff());
  }
  std::printf("[jacobian] KannalaBrandt to 100 deg: project %.3g, unproject %.3g (relative)\n", worstProject,
              worstUnproject);
  EXPECT_LT(worstProject, 1e-7);
  EXPECT_LT(worstUnproject, 1e-6);
}

TEST(KannalaBrandt, JacobiansOnTheAxis) {
  const auto camera = wideFisheye();
  const Eigen::Vector3d p(0, 0, 2.0);
  const Eigen::Matrix<double, 2, 3> J = camera.projectJacobian(p);
  EXPECT_NEAR(J(0, 0), camera.fx / 2.0, 1e-9);
  EXPECT_NEAR(J(1, 1), camera.fy / 2.0, 1e-9);
  const Eigen::Matrix<double, 3, 2> U = camera.unprojectJacobian(Eigen::Vector2d(camera.cx, camera.cy));
  EXPECT_NEAR(U(0, 0), 1.0 / camera.fx, 1e-12);
  EXPECT_NEAR(U(1, 1), 1.0 / camera.fy, 1e-12);
}

TEST(KannalaBrandt, AgreesWithOpenCvFisheye) {
  const auto camera = wideFisheye();
  std::vector<cv::Point3d> object;
  for (const Eigen::Vector3d& p : raysUpTo(85.0 * std::numbers::pi / 180.0, 200, 9)) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> pixels;
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const cv::Vec4d D(camera.k1, camera.k2, camera.k3, camera.k4);
  cv::fisheye::projectPoints(object, pixels, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  for (std::size_t i = 0; i < object.size(); ++i) {
    const Eigen::Vector2d px = camera.project(Eigen::Vector3d(object[i].x, object[i].y, object[i].z));
    EXPECT_NEAR(px.x(), pixels[i].x, 1e-8);
    EXPECT_NEAR(px.y(), pixels[i].y, 1e-8);
  }
}

TEST(KannalaBrandt, FieldOfView) {
  auto camera = wideFisheye();
  EXPECT_GT(camera.horizontalFieldOfViewDegrees(), 180.0);
  camera.maxAngle = std::numbers::pi / 2;
  EXPECT_TRUE(camera.inFieldOfView(Eigen::Vector3d(1, 0, 0.01)));
  EXPECT_FALSE(camera.inFieldOfView(Eigen::Vector3d(1, 0, -0.01)));
}

}  // namespace
}  // namespace orbis
