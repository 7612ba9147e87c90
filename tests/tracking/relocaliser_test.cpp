// EPnP and its RANSAC wrapper on synthetic correspondences with a known pose. The system-level
// relocalisation scenario (black frames in a synthetic sequence) is in tests/system.
#include <gtest/gtest.h>

#include <random>

#include "orbis/tracking/relocaliser.hpp"

namespace {

using namespace orbis;

PinholeCamera<double> testCamera() { return {520, 515, 318, 244, 640, 480}; }

SE3d randomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  SE3d::Tangent xi;
  for (int i = 0; i < 6; ++i) xi(i) = 0.5 * n(rng);
  return SE3d::exp(xi);
}

// World points in front of the camera Tcw (depth 1-6 m, inside the image), and their pixels.
void makeScene(const SE3d& Tcw, const PinholeCamera<double>& K, std::size_t n, std::mt19937_64& rng, Vector3dList& world,
               Vector2dList& pixels) {
  std::uniform_real_distribution<double> u(0, 640), v(0, 480), z(1, 6);
  world.clear();
  pixels.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d px(u(rng), v(rng));
    const double depth = z(rng);
    const Eigen::Vector3d pc = K.unproject(px, depth);
    world.push_back(Tcw.inverse() * pc);
    pixels.push_back(px);
  }
}

double rotationError(const SE3d& a, const SE3d& b) { return (a.so3().inverse() * b.so3()).log().norm(); }

// From five points on, the null space of M holds the exact solution in its first two vectors, so
// EPnP is exact on noise-free data (with four, the linearisation can settle elsewhere; RANSAC
// draws five).
TEST(Epnp, RecoversExactPoseFromFiveAndMorePoints) {
  std::mt19937_64 rng(11);
  const PinholeCamera<double> K = testCamera();
  for (std::size_t n : {5u, 6u, 50u}) {
    for (int trial = 0; trial < 20; ++trial) {
      const SE3d truth = randomPose(rng);
      Vector3dList world;
      Vector2dList pixels;
      makeScene(truth, K, n, rng, world, pixels);
      SE3d estimate;
      ASSERT_TRUE(solveEpnp(world, pixels, K, estimate));
      EXPECT_LT(rotationError(estimate, truth), 1e-5) << "n=" << n << " trial " << trial;
      EXPECT_LT((estimate.translation() - truth.translation()).norm(), 1e-5) << "n=" << n << " trial " << trial;
    }
  }
}

TEST(Epnp, NoisyPixelsGiveAClosePose) {
  std::mt19937_64 rng(12);
  const PinholeCamera<double> K = testCamera();
  std::normal_distribution<double> noise(0, 1.0);
  const SE3d truth = randomPose(rng);
  Vector3dList world;
  Vector2dList pixels;
  makeScene(truth, K, 200, rng, world, pixels);
  for (auto& p : pixels) p += Eigen::Vector2d(noise(rng), noise(rng));
  SE3d estimate;
  ASSERT_TRUE(solveEpnp(world, pixels, K, estimate));
  EXPECT_LT(rotationError(estimate, truth), 5e-3);
  EXPECT_LT((estimate.translation() - truth.translation()).norm(), 0.03);
}

TEST(Epnp, RejectsTooFewOrDegeneratePoints) {
  const PinholeCamera<double> K = testCamera();
  SE3d T;
  Vector3dList world(3, Eigen::Vector3d(0, 0, 2));
  Vector2dList pixels(3, Eigen::Vector2d(320, 240));
  EXPECT_FALSE(solveEpnp(world, pixels, K, T));
  world.assign(5, Eigen::Vector3d(1, 1, 3));  // all at one place: no control points
  pixels.assign(5, Eigen::Vector2d(100, 100));
  EXPECT_FALSE(solveEpnp(world, pixels, K, T));
}

TEST(PnpRansac, FindsPoseAndInliersAmongOutliersDeterministically) {
  std::mt19937_64 sceneRng(13);
  const PinholeCamera<double> K = testCamera();
  const SE3d truth = randomPose(sceneRng);
  Vector3dList world;
  Vector2dList pixels;
  makeScene(truth, K, 120, sceneRng, world, pixels);
  // 45% gross outliers: pixels moved anywhere in the image.
  std::uniform_real_distribution<double> u(0, 640), v(0, 480);
  std::vector<char> isOutlier(world.size(), 0);
  for (std::size_t i = 0; i < world.size(); i += 1)
    if (i % 20 < 9) {
      pixels[i] = Eigen::Vector2d(u(sceneRng), v(sceneRng));
      isOutlier[i] = 1;
    }
  const std::vector<float> sigma2(world.size(), 1.f);
  PnpRansacParams params;
  std::mt19937_64 rng1(7), rng2(7);
  const PnpRansacResult a = solvePnpRansac(world, pixels, sigma2, K, params, rng1);
  const PnpRansacResult b = solvePnpRansac(world, pixels, sigma2, K, params, rng2);
  ASSERT_TRUE(a.found);
  EXPECT_LT(rotationError(a.Tcw, truth), 1e-6);
  EXPECT_LT((a.Tcw.translation() - truth.translation()).norm(), 1e-6);
  int wrong = 0;
  for (std::size_t i = 0; i < world.size(); ++i) {
    // An outlier pixel may land within 2.4 px of its true projection by chance; count those apart.
    const Eigen::Vector3d pc = truth * world[i];
    const Eigen::Vector2d projected(K.fx * pc.x() / pc.z() + K.cx, K.fy * pc.y() / pc.z() + K.cy);
    const bool consistent = (projected - pixels[i]).squaredNorm() < params.chi2;
    wrong += (a.inlier[i] != 0) != consistent ? 1 : 0;
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(a.inliers, 60);
  // Same seed, same input: same answer.
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.inlier, b.inlier);
  EXPECT_EQ(a.Tcw.matrix(), b.Tcw.matrix());
}

TEST(PnpRansac, GivesUpOnPureNoise) {
  std::mt19937_64 sceneRng(14);
  const PinholeCamera<double> K = testCamera();
  Vector3dList world;
  Vector2dList pixels;
  makeScene(randomPose(sceneRng), K, 60, sceneRng, world, pixels);
  std::shuffle(pixels.begin(), pixels.end(), sceneRng);  // no correspondence is right
  PnpRansacParams params;
  params.minInliers = 30;
  std::mt19937_64 rng(3);
  const PnpRansacResult r = solvePnpRansac(world, pixels, std::vector<float>(world.size(), 1.f), K, params, rng);
  EXPECT_FALSE(r.found);
}

}  // namespace
