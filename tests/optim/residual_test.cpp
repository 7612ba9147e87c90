// Every residual's analytic Jacobians against central differences (through its manifold's
// update), on random well-conditioned configurations. The maximum discrepancy is printed.
#include "jacobian_check.hpp"

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/optim/pose_graph_residuals.hpp"
#include "orbis/optim/reprojection.hpp"
#include "orbis/optim/sim3_reprojection.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace orbis::optim {
namespace {

SE3d randomPose(std::mt19937& rng, double rotation, double translation) {
  std::normal_distribution<double> n(0.0, 1.0);
  SE3d::Tangent xi;
  for (int k = 0; k < 3; ++k) xi[k] = translation * n(rng);
  for (int k = 3; k < 6; ++k) xi[k] = rotation * n(rng);
  return SE3d::exp(xi);
}

// A world point in front of the camera at distance 2–10 m.
Eigen::Vector3d pointInFront(std::mt19937& rng, const SE3d& cameraFromWorld) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d pc(u(rng), u(rng), 6.0 + 4.0 * u(rng));
  return cameraFromWorld.inverse() * pc;
}

template <class R>
double worstOverTrials(std::uint32_t seed, const typename R::Observation& measurement,
                       const typename std::remove_pointer_t<decltype(R::camera)>& camera) {
  std::mt19937 rng(seed);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const SE3d pose = randomPose(rng, 0.8, 1.0);
    const R residual{measurement, &camera};
    const auto d = test::checkJacobians(residual, pose, pointInFront(rng, pose));
    worst = std::max(worst, d.relative());
  }
  return worst;
}

// The pose is camera-1-from-camera-2 and the point lives in camera 1: it must be in front of camera 2.
TEST(OptimResiduals, InversePoseReprojectionJacobians) {
  const PinholeCamera<double> camera{320.0, 310.0, 160.0, 120.0, 320, 240};
  std::mt19937 rng(7);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const SE3d T12 = randomPose(rng, 0.8, 1.0);
    const InversePoseReprojection<PinholeCamera<double>> residual{{150.0, 110.0}, &camera};
    const auto d = test::checkJacobians(residual, T12, pointInFront(rng, T12.inverse()));
    worst = std::max(worst, d.relative());
  }
  std::printf("InversePoseReprojection (2x6x3): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(OptimResiduals, MonoReprojectionJacobians) {
  const PinholeCamera<double> camera{458.0, 457.0, 367.0, 248.0, 752, 480};
  const double worst = worstOverTrials<MonoReprojection>(1, {300.0, 200.0}, camera);
  std::printf("MonoReprojection (2x6x3): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(OptimResiduals, StereoReprojectionJacobians) {
  const RectifiedStereoCamera<double> camera({718.9, 718.9, 607.2, 185.2, 1226, 370}, 0.537);
  const double worst = worstOverTrials<StereoReprojection>(2, {300.0, 200.0, 250.0}, camera);
  std::printf("StereoReprojection (3x6x3): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(OptimResiduals, RgbdReprojectionJacobians) {
  const RgbdCamera<double> camera({535.4, 539.2, 320.1, 247.6, 640, 480}, 40.0 / 535.4, 5000.0);
  const double worst = worstOverTrials<RgbdReprojection>(3, {310.0, 240.0, 290.0}, camera);
  std::printf("RgbdReprojection (3x6x3): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(OptimResiduals, DisparityReprojectionJacobians) {
  const RgbdCamera<double> camera({535.4, 539.2, 320.1, 247.6, 640, 480}, 40.0 / 535.4, 5000.0);
  std::mt19937 rng(5);
  double worst = 0.0;
  for (const double weight : {1.0, 8.0, 30.0}) {
    for (int trial = 0; trial < 50; ++trial) {
      const SE3d pose = randomPose(rng, 0.8, 1.0);
      const DisparityReprojection<RgbdCamera<double>> residual{{310.0, 240.0, 290.0}, &camera, weight};
      worst = std::max(worst, test::checkJacobians(residual, pose, pointInFront(rng, pose)).relative());
    }
  }
  std::printf("DisparityReprojection (3x6x3): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// The depth residual's rows are the keypoint's and the weighted disparity's: a keypoint found
// 0.5 px left of where its point projects, with a depth reading 0.2 px of disparity too near,
// gives (0.5, 0, -0.2 w) where the stereo residual mixes the two errors into (0.5, 0, 0.7).
TEST(OptimResiduals, DisparityReprojectionSeparatesKeypointAndDepthErrors) {
  const RgbdCamera<double> camera({535.4, 539.2, 320.1, 247.6, 640, 480}, 40.0 / 535.4, 5000.0);
  const Eigen::Vector3d pc(0.1, -0.2, 1.6);
  const Eigen::Vector3d ideal = camera.project(pc);
  const Eigen::Vector3d measured(ideal.x() - 0.5, ideal.y(), ideal.z() - 0.5 - 0.2);
  Eigen::Vector3d stereo, depth;
  Reprojection<RgbdCamera<double>>{measured, &camera}.evaluate(SE3d(), pc, stereo, nullptr, nullptr);
  DisparityReprojection<RgbdCamera<double>>{measured, &camera, 8.0}.evaluate(SE3d(), pc, depth, nullptr, nullptr);
  EXPECT_NEAR(stereo.x(), 0.5, 1e-9);
  EXPECT_NEAR(stereo.z(), 0.7, 1e-9);
  EXPECT_NEAR(depth.x(), 0.5, 1e-9);
  EXPECT_NEAR(depth.y(), 0.0, 1e-9);
  EXPECT_NEAR(depth.z(), 8.0 * -0.2, 1e-9);
}

TEST(OptimResiduals, RelativePoseSE3Jacobians) {
  std::mt19937 rng(4);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    // Far from satisfied (large residual) so the J_l⁻¹/J_r⁻¹ factors matter.
    const RelativePoseSE3 residual{randomPose(rng, 0.7, 1.0)};
    const auto d = test::checkJacobians(residual, randomPose(rng, 0.7, 2.0), randomPose(rng, 0.7, 2.0));
    worst = std::max(worst, d.relative());
  }
  std::printf("RelativePoseSE3 (6x6x6): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

Sim3d randomSim3(std::mt19937& rng, double rotation, double translation, double logScale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Sim3d::Tangent xi;
  for (int k = 0; k < 3; ++k) xi[k] = translation * n(rng);
  for (int k = 3; k < 6; ++k) xi[k] = rotation * n(rng);
  xi[6] = logScale * n(rng);
  return Sim3d::exp(xi);
}

TEST(OptimResiduals, RelativePoseSim3Jacobians) {
  std::mt19937 rng(7);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const RelativePoseSim3 residual{randomSim3(rng, 0.7, 1.0, 0.3)};
    const auto d = test::checkJacobians(residual, randomSim3(rng, 0.7, 2.0, 0.3), randomSim3(rng, 0.7, 2.0, 0.3));
    worst = std::max(worst, d.relative());
  }
  std::printf("RelativePoseSim3 (7x7x7): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// A point ahead of a camera at 2–10 units, expressed through `toPoint` (the inverse of the map
// the residual applies).
Eigen::Vector3d pointSeenThrough(std::mt19937& rng, const Sim3d& toPoint) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return toPoint * Eigen::Vector3d(u(rng), u(rng), 6.0 + 4.0 * u(rng));
}

// Loop closing's Sim(3) refinement: camera 1 sees camera 2's points through S12, camera 2 sees
// camera 1's through S12⁻¹; scales up to e^{±0.9} as a monocular map drifts.
TEST(OptimResiduals, Sim3ReprojectionJacobians) {
  const PinholeCamera<double> camera{250.0, 250.0, 160.0, 120.0, 320, 240};
  std::mt19937 rng(13);
  double worstDirect = 0.0, worstInverse = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const Sim3d S12 = randomSim3(rng, 0.7, 1.0, 0.3);
    const MonoSim3Reprojection direct{{150.0, 110.0}, &camera};
    worstDirect = std::max(worstDirect, test::checkJacobians(direct, S12, pointSeenThrough(rng, S12.inverse())).relative());
    const MonoInverseSim3Reprojection inverse{{170.0, 100.0}, &camera};
    worstInverse = std::max(worstInverse, test::checkJacobians(inverse, S12, pointSeenThrough(rng, S12)).relative());
  }
  std::printf("Sim3Reprojection (2x7x3): max relative discrepancy %.3e\n", worstDirect);
  std::printf("InverseSim3Reprojection (2x7x3): max relative discrepancy %.3e\n", worstInverse);
  EXPECT_LT(worstDirect, 1e-6);
  EXPECT_LT(worstInverse, 1e-6);
}

// A direction up to maxDegrees off the camera's axis, 2–10 m away, in the world.
Eigen::Vector3d pointOffAxis(std::mt19937& rng, double maxDegrees, const SE3d& cameraFromWorld) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double theta = maxDegrees * std::numbers::pi / 180 * u(rng), azimuth = 2 * std::numbers::pi * u(rng);
  const Eigen::Vector3d ray(std::sin(theta) * std::cos(azimuth), std::sin(theta) * std::sin(azimuth), std::cos(theta));
  return cameraFromWorld.inverse() * ((2.0 + 8.0 * u(rng)) * ray);
}

// The fisheye sensor's residuals in lens pixels (MonocularFisheye's BA and Sim(3) refinement):
// the generic reprojections on the Kannala–Brandt lens, for points up to 100 degrees off axis.
TEST(OptimResiduals, KannalaBrandtReprojectionJacobians) {
  KannalaBrandtCamera<double> lens;
  lens.fx = 199.7, lens.fy = 201.3, lens.cx = 320, lens.cy = 240;
  lens.k1 = 0.01, lens.k2 = -0.002, lens.k3 = 0.0005, lens.k4 = -0.0001;
  lens.width = 640, lens.height = 480;
  std::mt19937 rng(17);
  double worstPose = 0, worstSim3 = 0, worstInverseSim3 = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const SE3d pose = randomPose(rng, 0.8, 1.0);
    const Reprojection<KannalaBrandtCamera<double>> residual{{300.0, 200.0}, &lens};
    worstPose = std::max(worstPose, test::checkJacobians(residual, pose, pointOffAxis(rng, 100, pose)).relative());
    const Sim3d S12 = randomSim3(rng, 0.7, 1.0, 0.3);
    const Sim3Reprojection<KannalaBrandtCamera<double>> direct{{150.0, 110.0}, &lens};
    const InverseSim3Reprojection<KannalaBrandtCamera<double>> inverse{{170.0, 100.0}, &lens};
    // Camera 1 sees S12·p (p in camera 2) and camera 2 sees S12⁻¹·p (p in camera 1), each up to
    // 100 degrees off its axis.
    const Eigen::Vector3d seenBy1 = pointOffAxis(rng, 100, SE3d());
    worstSim3 = std::max(worstSim3, test::checkJacobians(direct, S12, S12.inverse() * seenBy1).relative());
    const Eigen::Vector3d seenBy2 = pointOffAxis(rng, 100, SE3d());
    worstInverseSim3 = std::max(worstInverseSim3, test::checkJacobians(inverse, S12, S12 * seenBy2).relative());
  }
  std::printf("Reprojection<KannalaBrandt> (2x6x3): max relative discrepancy %.3e\n", worstPose);
  std::printf("Sim3Reprojection<KannalaBrandt> (2x7x3): %.3e, inverse %.3e\n", worstSim3, worstInverseSim3);
  EXPECT_LT(worstPose, 1e-6);
  EXPECT_LT(worstSim3, 1e-6);
  EXPECT_LT(worstInverseSim3, 1e-6);
}

// With scale 1 the Sim(3) residuals are the SE(3) ones: same values, and the first six Jacobian
// columns equal (the seventh, the scale, is what a monocular loop adds).
TEST(OptimResiduals, Sim3ReprojectionReducesToSE3AtUnitScale) {
  const PinholeCamera<double> camera{250.0, 250.0, 160.0, 120.0, 320, 240};
  std::mt19937 rng(17);
  const SE3d T12 = randomPose(rng, 0.5, 1.0);
  const Sim3d S12(T12);
  const Eigen::Vector3d p2 = pointSeenThrough(rng, S12.inverse()), p1 = pointSeenThrough(rng, S12);
  Eigen::Vector2d a, b;
  Eigen::Matrix<double, 2, 7> j7;
  Eigen::Matrix<double, 2, 6> j6;
  MonoSim3Reprojection{{150.0, 110.0}, &camera}.evaluate(S12, p2, a, &j7, nullptr);
  MonoReprojection{{150.0, 110.0}, &camera}.evaluate(T12, p2, b, &j6, nullptr);
  EXPECT_LT((a - b).norm(), 1e-9);
  EXPECT_LT((j7.leftCols<6>() - j6).norm(), 1e-9 * j6.norm());
  MonoInverseSim3Reprojection{{170.0, 100.0}, &camera}.evaluate(S12, p1, a, &j7, nullptr);
  InversePoseReprojection<PinholeCamera<double>>{{170.0, 100.0}, &camera}.evaluate(T12, p1, b, &j6, nullptr);
  EXPECT_LT((a - b).norm(), 1e-9);
  EXPECT_LT((j7.leftCols<6>() - j6).norm(), 1e-9 * j6.norm());
}

TEST(OptimResiduals, JacobianCheckDetectsAWrongJacobian) {
  // The harness itself must be able to fail: a residual with a deliberately wrong sign.
  struct Wrong : MonoReprojection {
    void evaluate(const SE3d& t, const Eigen::Vector3d& x, Eigen::Vector2d& r,
                  Eigen::Matrix<double, 2, 6>* jp, Eigen::Matrix<double, 2, 3>* jx) const {
      MonoReprojection::evaluate(t, x, r, jp, jx);
      if (jp) jp->rightCols<3>() *= -1.0;
    }
  };
  const PinholeCamera<double> camera{458.0, 457.0, 367.0, 248.0, 752, 480};
  std::mt19937 rng(5);
  const SE3d pose = randomPose(rng, 0.5, 1.0);
  const Wrong wrong{{{300.0, 200.0}, &camera}};
  EXPECT_GT(test::checkJacobians(wrong, pose, pointInFront(rng, pose)).relative(), 1e-2);
}

}  // namespace
}  // namespace orbis::optim
