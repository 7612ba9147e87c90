// One generic harness for every camera model: round trips, analytic vs numeric Jacobians,
// and the traits. A new model is tested by adding it to CameraTypes and to makeCamera().
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "orbis/camera/camera_model.hpp"
#include "orbis/camera/kannala_brandt.hpp"

namespace orbis {
namespace {

// --- concept negative checks: these types must not pass as cameras -------------------------
struct NotACameraNoJacobian {
  using Scalar = double;
  static constexpr int kObservationDim = 2;
  static constexpr bool kMetricDepth = false;
  Eigen::Vector2d project(const Eigen::Vector3d& p) const { return p.head<2>(); }
};
struct NotACameraWrongDim : PinholeCamera<double> {
  static constexpr int kObservationDim = 4;
};
static_assert(!CameraModel<int>);
static_assert(!CameraModel<NotACameraNoJacobian>);
static_assert(!CameraModel<NotACameraWrongDim>);
static_assert(!CameraModel<PinholeCamera<int>>);
static_assert(CameraTraits<RgbdCamera<float>>::kObservationDim == 3);
static_assert(!CameraTraits<PinholeCamera<double>>::kMetricDepth);

// TUM freiburg1-like intrinsics; baseline 0.08 m is ORB-SLAM2's virtual Kinect baseline.
template <class S>
PinholeCamera<S> testPinhole() {
  return {S(517.3), S(516.5), S(318.6), S(255.3), 640, 480};
}
template <class C> C makeCamera();
template <> PinholeCamera<double> makeCamera() { return testPinhole<double>(); }
template <> PinholeCamera<float> makeCamera() { return testPinhole<float>(); }
template <> RectifiedStereoCamera<double> makeCamera() { return {testPinhole<double>(), 0.11}; }
template <> RectifiedStereoCamera<float> makeCamera() { return {testPinhole<float>(), 0.11f}; }
template <> RgbdCamera<double> makeCamera() { return {testPinhole<double>(), 0.08, 5000.0}; }
template <> RgbdCamera<float> makeCamera() { return {testPinhole<float>(), 0.08f, 5000.0f}; }
// A 640x480 fisheye of about 190 degrees across (coefficients of ORB-SLAM3's TUM-VI file).
template <class S>
KannalaBrandtCamera<S> testFisheye() {
  KannalaBrandtCamera<S> c;
  c.fx = S(190.98), c.fy = S(190.97), c.cx = S(318.4), c.cy = S(241.7);
  c.k1 = S(0.0034), c.k2 = S(0.0007), c.k3 = S(-0.0020), c.k4 = S(0.0003);
  c.width = 640, c.height = 480;
  return c;
}
template <> KannalaBrandtCamera<double> makeCamera() { return testFisheye<double>(); }
template <> KannalaBrandtCamera<float> makeCamera() { return testFisheye<float>(); }

template <class C> std::string modelName();
template <> std::string modelName<PinholeCamera<double>>() { return "PinholeCamera<double>"; }
template <> std::string modelName<PinholeCamera<float>>() { return "PinholeCamera<float>"; }
template <> std::string modelName<RectifiedStereoCamera<double>>() { return "RectifiedStereoCamera<double>"; }
template <> std::string modelName<RectifiedStereoCamera<float>>() { return "RectifiedStereoCamera<float>"; }
template <> std::string modelName<RgbdCamera<double>>() { return "RgbdCamera<double>"; }
template <> std::string modelName<RgbdCamera<float>>() { return "RgbdCamera<float>"; }
template <> std::string modelName<KannalaBrandtCamera<double>>() { return "KannalaBrandtCamera<double>"; }
template <> std::string modelName<KannalaBrandtCamera<float>>() { return "KannalaBrandtCamera<float>"; }

// Points in front of the camera, 0.3 m to 30 m deep, spread over and beyond the image.
std::vector<Eigen::Vector3d> randomPoints(unsigned seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> lateral(-1.0, 1.0), depth(0.3, 30.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double z = depth(rng);
    points.emplace_back(lateral(rng) * z, 0.8 * lateral(rng) * z, z);
  }
  return points;
}

template <class C>
class CameraModelTest : public ::testing::Test {};

using CameraTypes = ::testing::Types<PinholeCamera<double>, RectifiedStereoCamera<double>, RgbdCamera<double>,
                                     PinholeCamera<float>, RectifiedStereoCamera<float>, RgbdCamera<float>,
                                     KannalaBrandtCamera<double>, KannalaBrandtCamera<float>>;
TYPED_TEST_SUITE(CameraModelTest, CameraTypes);

TYPED_TEST(CameraModelTest, ProjectUnprojectRoundTrip) {
  using C = TypeParam;
  using S = typename C::Scalar;
  const C camera = makeCamera<C>();
  const double tolerance = std::is_same_v<S, float> ? 2e-5 : 1e-11;  // relative to depth
  for (const Eigen::Vector3d& p : randomPoints(7, 500)) {
    const Eigen::Matrix<S, 3, 1> pc = p.cast<S>();
    ASSERT_TRUE(C::inFront(pc));
    const auto obs = camera.project(pc);
    const Eigen::Matrix<S, 3, 1> back = camera.unproject(obs.template head<2>().eval(), pc.z());
    EXPECT_LT((back - pc).template cast<double>().norm(), tolerance * p.z()) << p.transpose();
    if constexpr (C::kObservationDim == 3) {
      // Disparity carries the depth: the observation alone gives the point back, up to the
      // rounding of uL and uR (a few ulps of ~1000 px) magnified by dZ/d(disparity) = Z^2 / bf.
      const Eigen::Matrix<S, 3, 1> fromObservation = camera.unproject(obs);
      const double pixelRounding = std::is_same_v<S, float> ? 2e-4 : 1e-12;
      const double bound = tolerance * p.z() + pixelRounding * p.z() * p.z() / double(camera.bf()) * 2;
      EXPECT_LT((fromObservation - pc).template cast<double>().norm(), bound) << p.transpose();
    }
  }
  EXPECT_FALSE(C::inFront(Eigen::Matrix<S, 3, 1>(0, 0, -1)));
}

// Central differences on the camera cast to double, so float models are checked against an
// accurate reference too.
TYPED_TEST(CameraModelTest, ProjectJacobianMatchesNumericDifferentiation) {
  using C = TypeParam;
  using S = typename C::Scalar;
  const C camera = makeCamera<C>();
  const auto reference = camera.template cast<double>();
  double maxDiff = 0, maxRelative = 0;
  for (const Eigen::Vector3d& p : randomPoints(11, 300)) {
    const Eigen::Matrix<double, C::kObservationDim, 3> analytic =
        camera.projectJacobian(p.cast<S>()).template cast<double>();
    Eigen::Matrix<double, C::kObservationDim, 3> numeric;
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6 * p.z();
      Eigen::Vector3d plus = p, minus = p;
      plus[k] += h;
      minus[k] -= h;
      numeric.col(k) = (reference.project(plus) - reference.project(minus)) / (2 * h);
    }
    const double diff = (analytic - numeric).cwiseAbs().maxCoeff();
    maxDiff = std::max(maxDiff, diff);
    maxRelative = std::max(maxRelative, diff / std::max(1.0, numeric.cwiseAbs().maxCoeff()));
  }
  std::printf("[jacobian] %s projectJacobian max|diff| = %.3g (relative %.3g)\n", modelName<C>().c_str(),
              maxDiff, maxRelative);
  const double tolerance = std::is_same_v<S, float> ? 1e-5 : 1e-7;
  EXPECT_LT(maxRelative, tolerance);
}

TYPED_TEST(CameraModelTest, InImageBounds) {
  const TypeParam camera = makeCamera<TypeParam>();
  EXPECT_TRUE(camera.inImage(0, 0));
  EXPECT_TRUE(camera.inImage(639.5, 479.5));
  EXPECT_FALSE(camera.inImage(640, 10));
  EXPECT_FALSE(camera.inImage(10, 480));
  EXPECT_FALSE(camera.inImage(-0.5, 10));
}

TEST(StereoCamera, UrIsUlMinusBfOverDepth) {
  const auto camera = makeCamera<RectifiedStereoCamera<double>>();
  EXPECT_DOUBLE_EQ(camera.bf(), 517.3 * 0.11);
  const Eigen::Vector3d obs = camera.project(Eigen::Vector3d(0.4, -0.2, 2.5));
  EXPECT_NEAR(obs.x() - obs.z(), camera.bf() / 2.5, 1e-12);
  EXPECT_NEAR(camera.depthFromDisparity(obs.x() - obs.z()), 2.5, 1e-12);
}

TEST(RgbdCamera, DepthReadingBecomesStereoObservation) {
  const auto camera = makeCamera<RgbdCamera<double>>();
  EXPECT_NEAR(camera.bf(), 517.3 * 0.08, 1e-12);
  // TUM depth PNGs store 5000 units per metre.
  const double depth = camera.metricDepth(7500.0);
  EXPECT_DOUBLE_EQ(depth, 1.5);
  const Eigen::Vector3d obs = camera.observationFromDepth(100.0, 200.0, depth);
  EXPECT_DOUBLE_EQ(obs.x(), 100.0);
  EXPECT_DOUBLE_EQ(obs.y(), 200.0);
  EXPECT_NEAR(obs.z(), 100.0 - camera.bf() / 1.5, 1e-12);
  // The same point, projected, gives the same observation.
  const Eigen::Vector3d point = camera.unproject(Eigen::Vector2d(100.0, 200.0), depth);
  EXPECT_LT((camera.project(point) - obs).norm(), 1e-9);
}

TEST(CameraTraits, CloseFarThreshold) {
  const auto stereo = makeCamera<RectifiedStereoCamera<double>>();
  EXPECT_DOUBLE_EQ(CameraTraits<RectifiedStereoCamera<double>>::closeDepthThreshold(stereo), 40 * 0.11);
  const RectifiedStereoCamera<double> overridden(stereo.pinhole, 0.11, 35 * 0.11);
  EXPECT_DOUBLE_EQ(overridden.closeDepthThreshold(), 35 * 0.11);
  const auto rgbd = makeCamera<RgbdCamera<double>>();
  EXPECT_DOUBLE_EQ(rgbd.closeDepthThreshold(), 40 * 0.08);
  const RgbdCamera<double> rgbdOverridden(rgbd.pinhole, 0.08, 5000.0, 2.0);
  EXPECT_DOUBLE_EQ(rgbdOverridden.closeDepthThreshold(), 2.0);
  EXPECT_DOUBLE_EQ(rgbdOverridden.depthScale, 5000.0);
  // Monocular: no metric depth, so nothing is ever "close".
  EXPECT_TRUE(std::isinf(makeCamera<PinholeCamera<double>>().closeDepthThreshold()));
}

// A rectified pair's far keypoints enter BA as monocular (their small disparity carries the
// rectification's sub-pixel offset as a scale bias); a depth sensor keeps its depth everywhere.
TEST(CameraTraits, BundleAdjustmentDepthLimit) {
  const auto stereo = makeCamera<RectifiedStereoCamera<double>>();
  EXPECT_DOUBLE_EQ(bundleAdjustmentDepthLimit(stereo), stereo.closeDepthThreshold());
  EXPECT_DOUBLE_EQ(bundleAdjustmentDepthLimit(RectifiedStereoCamera<double>(stereo.pinhole, 0.11, 2.0)), 2.0);
  EXPECT_TRUE(std::isinf(bundleAdjustmentDepthLimit(makeCamera<RgbdCamera<double>>())));
  EXPECT_TRUE(std::isinf(bundleAdjustmentDepthLimit(makeCamera<PinholeCamera<double>>())));
}

TEST(CameraCast, KeepsEveryParameter) {
  const RgbdCamera<double> camera(testPinhole<double>(), 0.08, 1000.0, 3.0);
  const RgbdCamera<float> f = camera.cast<float>();
  EXPECT_FLOAT_EQ(f.pinhole.cx, 318.6f);
  EXPECT_EQ(f.pinhole.width, 640);
  EXPECT_FLOAT_EQ(f.baseline, 0.08f);
  EXPECT_FLOAT_EQ(f.depthScale, 1000.0f);
  EXPECT_FLOAT_EQ(f.closeDepth, 3.0f);
}

}  // namespace
}  // namespace orbis
