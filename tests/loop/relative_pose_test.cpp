// The SE(3) loop transform: RANSAC + refinement recovering a known transform from noisy matches
// with outliers (the two-way residuals' Jacobians are checked in tests/optim/residual_test.cpp).
#include <gtest/gtest.h>

#include <random>

#include "orbis/loop/relative_pose.hpp"

namespace {

using namespace orbis;
using namespace orbis::loop;

PinholeCamera<double> intrinsics() { return {320, 310, 160, 120, 320, 240}; }

SE3d someTransform() {
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.3, -0.1, 0.2, 0.05, -0.2, 0.1;
  return SE3d::exp(xi);
}

Eigen::Vector2d project(const PinholeCamera<double>& K, const Eigen::Vector3d& p) { return K.project(p); }

// Points in front of both cameras with their exact (or noisy) keypoints; `outliers` of them get
// a wrong partner point.
std::vector<PointPair> makePairs(const SE3d& T12, int count, int outliers, double pixelNoise, std::mt19937& rng) {
  const PinholeCamera<double> K = intrinsics();
  std::uniform_real_distribution<double> xy(-1.5, 1.5), depth(2.0, 6.0);
  std::normal_distribution<double> noise(0.0, pixelNoise);
  std::vector<PointPair> pairs;
  const SE3d T21 = T12.inverse();
  while (static_cast<int>(pairs.size()) < count) {
    const Eigen::Vector3d p2(xy(rng), xy(rng), depth(rng));
    const Eigen::Vector3d p1 = T12 * p2;
    if (p1.z() < 0.5) continue;
    PointPair pair;
    pair.p1 = p1;
    pair.p2 = T21 * p1;
    pair.obs1 = project(K, p1) + Eigen::Vector2d(noise(rng), noise(rng));
    pair.obs2 = project(K, p2) + Eigen::Vector2d(noise(rng), noise(rng));
    pairs.push_back(pair);
  }
  for (int k = 0; k < outliers; ++k) pairs[static_cast<std::size_t>(k) * 3].p2 += Eigen::Vector3d(0.8, -0.5, 0.6);
  return pairs;
}

TEST(RelativePose, RansacAndRefinementRecoverTheTransformDespiteOutliers) {
  std::mt19937 data(5);
  const SE3d truth = someTransform();
  const std::vector<PointPair> pairs = makePairs(truth, 120, 30, 0.7, data);
  std::mt19937 rng(7);
  const RelativePoseEstimate estimate = estimateRelativePoseRansac(pairs, intrinsics(), {}, rng);
  ASSERT_TRUE(estimate.found);
  // Every planted outlier rejected (pairs 0, 3, ..., 87), nearly every other pair kept.
  for (int k = 0; k < 30; ++k) EXPECT_FALSE(estimate.inliers[static_cast<std::size_t>(k) * 3]) << k;
  EXPECT_GE(estimate.inlierCount, 85);
  SE3d T12 = estimate.T12;
  std::vector<char> inliers = estimate.inliers;
  const int kept = refineRelativePose(pairs, intrinsics(), T12, inliers);
  EXPECT_GE(kept, 85);
  const Eigen::Matrix<double, 6, 1> error = (T12 * truth.inverse()).log();
  EXPECT_LT(error.head<3>().norm(), 0.01);  // metres
  EXPECT_LT(error.tail<3>().norm(), 0.002);  // radians
}

TEST(RelativePose, RansacFailsWithoutEnoughConsistentMatches) {
  std::mt19937 data(9);
  std::vector<PointPair> pairs = makePairs(someTransform(), 40, 0, 0.5, data);
  // Scramble the partners: no rigid transform explains more than a handful.
  for (std::size_t k = 0; k + 1 < pairs.size(); k += 2) std::swap(pairs[k].p2, pairs[k + 1].p2);
  std::mt19937 rng(7);
  EXPECT_FALSE(estimateRelativePoseRansac(pairs, intrinsics(), {}, rng).found);
}

TEST(RelativePose, SameSeedSameEstimate) {
  std::mt19937 data(11);
  const std::vector<PointPair> pairs = makePairs(someTransform(), 60, 15, 1.0, data);
  std::mt19937 a(42), b(42);
  const RelativePoseEstimate ea = estimateRelativePoseRansac(pairs, intrinsics(), {}, a);
  const RelativePoseEstimate eb = estimateRelativePoseRansac(pairs, intrinsics(), {}, b);
  ASSERT_TRUE(ea.found);
  EXPECT_EQ(ea.T12.matrix(), eb.T12.matrix());
  EXPECT_EQ(ea.inliers, eb.inliers);
}

}  // namespace
