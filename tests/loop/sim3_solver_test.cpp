// The Sim(3) loop transform of monocular maps: Horn's closed form, RANSAC over it with the
// two-image reprojection test, and the two-way refinement (its residuals' Jacobians are checked
// in tests/optim/residual_test.cpp).
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "orbis/loop/sim3_solver.hpp"

namespace {

using namespace orbis;
using namespace orbis::loop;

PinholeCamera<double> intrinsics() { return {250, 250, 160, 120, 320, 240}; }

// A loop's similarity: the current keyframe's map drifted to 1.7 times the loop side's scale.
Sim3d someSimilarity(double scale = 1.7) {
  Sim3d::Tangent xi;
  xi << 0.3, -0.1, 0.2, 0.05, -0.2, 0.1, std::log(scale);
  return Sim3d::exp(xi);
}

// Points seen by both cameras with their (noisy) keypoints; the first `outliers` pairs get a
// wrong partner: the same keypoints but another point's coordinates in camera 2.
std::vector<PointPair> makePairs(const Sim3d& S12, int count, int outliers, double pixelNoise, std::mt19937& rng) {
  const PinholeCamera<double> K = intrinsics();
  std::uniform_real_distribution<double> xy(-1.2, 1.2), depth(2.0, 6.0);
  std::normal_distribution<double> noise(0.0, pixelNoise);
  std::vector<PointPair> pairs;
  while (static_cast<int>(pairs.size()) < count) {
    const Eigen::Vector3d p2(xy(rng), xy(rng), depth(rng));
    const Eigen::Vector3d p1 = S12 * p2;
    if (p1.z() < 0.5) continue;
    const Eigen::Vector2d u1 = K.project(p1), u2 = K.project(p2);
    if (!K.inImage(u1.x(), u1.y()) || !K.inImage(u2.x(), u2.y())) continue;
    PointPair pair;
    pair.p1 = p1;
    pair.p2 = p2;
    pair.obs1 = K.project(p1) + Eigen::Vector2d(noise(rng), noise(rng));
    pair.obs2 = K.project(p2) + Eigen::Vector2d(noise(rng), noise(rng));
    pairs.push_back(pair);
  }
  for (int k = 0; k < outliers; ++k) {
    const auto from = static_cast<std::size_t>(count - 1 - k);
    pairs[static_cast<std::size_t>(k)].p2 = pairs[from].p2 + Eigen::Vector3d(0.3, -0.2, 0.1);
  }
  return pairs;
}

double rotationError(const Sim3d& a, const Sim3d& b) { return (a.so3().inverse() * b.so3()).log().norm(); }

TEST(Sim3Solver, HornRecoversAKnownSimilarityExactly) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 2.0);
  for (const double scale : {0.3, 1.0, 1.7, 6.0}) {
    const Sim3d truth = someSimilarity(scale);
    Eigen::Matrix3Xd source(3, 12), target(3, 12);
    for (int c = 0; c < 12; ++c) {
      source.col(c) = Eigen::Vector3d(n(rng), n(rng), n(rng));
      target.col(c) = truth * Eigen::Vector3d(source.col(c));
    }
    for (const int points : {3, 12}) {
      const std::optional<Sim3d> S = alignSim3(source.leftCols(points), target.leftCols(points));
      ASSERT_TRUE(S) << scale;
      EXPECT_NEAR(S->scale(), scale, 1e-9 * scale);
      EXPECT_LT(rotationError(*S, truth), 1e-9);
      EXPECT_LT((S->translation() - truth.translation()).norm(), 1e-9 * (1 + truth.translation().norm()));
    }
  }
}

TEST(Sim3Solver, FixedScaleGivesTheRigidMotion) {
  // Rigid data: the free and the fixed-scale solutions agree, and the fixed one is exactly 1.
  const Sim3d truth = someSimilarity(1.0);
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 2.0);
  Eigen::Matrix3Xd source(3, 8), target(3, 8);
  for (int c = 0; c < 8; ++c) {
    source.col(c) = Eigen::Vector3d(n(rng), n(rng), n(rng));
    target.col(c) = truth * Eigen::Vector3d(source.col(c));
  }
  const std::optional<Sim3d> S = alignSim3(source, target, /*fixScale=*/true);
  ASSERT_TRUE(S);
  EXPECT_EQ(S->scale(), 1.0);
  EXPECT_LT(rotationError(*S, truth), 1e-9);
  EXPECT_LT((S->translation() - truth.translation()).norm(), 1e-9);
}

TEST(Sim3Solver, DegenerateSetsAreRefused) {
  const Sim3d truth = someSimilarity();
  Eigen::Matrix3Xd line(3, 5), lineTarget(3, 5);
  for (int c = 0; c < 5; ++c) {
    line.col(c) = Eigen::Vector3d(0.1, -0.2, 2.0) + c * Eigen::Vector3d(0.3, 0.1, 0.5);
    lineTarget.col(c) = truth * Eigen::Vector3d(line.col(c));
  }
  EXPECT_FALSE(alignSim3(line, lineTarget));                               // collinear
  EXPECT_FALSE(alignSim3(line.leftCols(3), lineTarget.leftCols(3), true));  // fixed scale too
  EXPECT_FALSE(alignSim3(line.leftCols(2), lineTarget.leftCols(2)));        // too few
  Eigen::Matrix3Xd same(3, 4);
  same.colwise() = Eigen::Vector3d(1, 2, 3);
  EXPECT_FALSE(alignSim3(same, same));  // coincident
  // A plane is enough.
  Eigen::Matrix3Xd plane(3, 3), planeTarget(3, 3);
  plane << 0, 1, 0, 0, 0, 1, 2, 2, 2;
  for (int c = 0; c < 3; ++c) planeTarget.col(c) = truth * Eigen::Vector3d(plane.col(c));
  EXPECT_TRUE(alignSim3(plane, planeTarget));
  // RANSAC over matches that all lie on one line finds nothing.
  std::vector<PointPair> pairs;
  const PinholeCamera<double> K = intrinsics();
  for (int c = 0; c < 40; ++c) {
    PointPair pair;
    pair.p2 = Eigen::Vector3d(-0.5, -0.3, 2.0) + 0.02 * c * Eigen::Vector3d(1.0, 0.5, 0.5);
    pair.p1 = truth * pair.p2;
    pair.obs1 = K.project(pair.p1);
    pair.obs2 = K.project(pair.p2);
    pairs.push_back(pair);
  }
  std::mt19937 rng(1);
  EXPECT_FALSE(estimateSim3Ransac(pairs, K, {}, rng).found);
}

TEST(Sim3Solver, RansacRecoversTheSimilarityFromExactMatches) {
  std::mt19937 data(5);
  const Sim3d truth = someSimilarity();
  const std::vector<PointPair> pairs = makePairs(truth, 60, 0, 0.0, data);
  std::mt19937 rng(7);
  const Sim3Estimate estimate = estimateSim3Ransac(pairs, intrinsics(), {}, rng);
  ASSERT_TRUE(estimate.found);
  EXPECT_EQ(estimate.inlierCount, 60);
  EXPECT_LT(estimate.iterations, 10);  // every triple is good: the early stop ends it at once
  EXPECT_NEAR(estimate.S12.scale(), truth.scale(), 1e-9);
  EXPECT_LT(rotationError(estimate.S12, truth), 1e-9);
  EXPECT_LT((estimate.S12.translation() - truth.translation()).norm(), 1e-9);
}

TEST(Sim3Solver, HalfOutliersAreRejectedAndRefinementRecoversTheSimilarity) {
  std::mt19937 data(5);
  const Sim3d truth = someSimilarity();
  // Keypoint noise of one pixel, and 3-D points perturbed as a map's are (2% of their depth).
  std::vector<PointPair> pairs = makePairs(truth, 120, 60, 1.0, data);
  std::normal_distribution<double> jitter(0.0, 0.02);
  for (PointPair& p : pairs) {
    p.p1 *= 1.0 + jitter(data);
    p.p2 *= 1.0 + jitter(data);
  }
  std::mt19937 rng(7);
  const Sim3Estimate estimate = estimateSim3Ransac(pairs, intrinsics(), {}, rng);
  ASSERT_TRUE(estimate.found);
  for (int k = 0; k < 60; ++k) EXPECT_FALSE(estimate.inliers[static_cast<std::size_t>(k)]) << k;
  EXPECT_GE(estimate.inlierCount, 40);
  Sim3d S12 = estimate.S12;
  std::vector<char> inliers = estimate.inliers;
  const int kept = refineSim3(pairs, intrinsics(), S12, inliers);
  EXPECT_GE(kept, 50);
  for (int k = 0; k < 60; ++k) EXPECT_FALSE(inliers[static_cast<std::size_t>(k)]) << k;
  std::printf("Sim3 RANSAC: %d inliers of 120 in %d hypotheses, %d after refinement; scale %.4f (truth %.4f)\n",
              estimate.inlierCount, estimate.iterations, kept, S12.scale(), truth.scale());
  EXPECT_NEAR(S12.scale(), truth.scale(), 0.02 * truth.scale());
  EXPECT_LT(rotationError(S12, truth), 0.005);
  EXPECT_LT((S12.translation() - truth.translation()).norm(), 0.05);
}

TEST(Sim3Solver, RansacFailsWithoutEnoughConsistentMatches) {
  std::mt19937 data(9);
  std::vector<PointPair> pairs = makePairs(someSimilarity(), 40, 0, 0.5, data);
  for (std::size_t k = 0; k + 1 < pairs.size(); k += 2) std::swap(pairs[k].p2, pairs[k + 1].p2);
  std::mt19937 rng(7);
  EXPECT_FALSE(estimateSim3Ransac(pairs, intrinsics(), {}, rng).found);
}

TEST(Sim3Solver, SameSeedSameEstimateBitForBit) {
  std::mt19937 data(11);
  const std::vector<PointPair> pairs = makePairs(someSimilarity(), 80, 30, 1.0, data);
  std::mt19937 a(42), b(42);
  Sim3Estimate ea = estimateSim3Ransac(pairs, intrinsics(), {}, a);
  Sim3Estimate eb = estimateSim3Ransac(pairs, intrinsics(), {}, b);
  ASSERT_TRUE(ea.found && eb.found);
  refineSim3(pairs, intrinsics(), ea.S12, ea.inliers);
  refineSim3(pairs, intrinsics(), eb.S12, eb.inliers);
  const Eigen::Matrix4d ma = ea.S12.matrix(), mb = eb.S12.matrix();
  EXPECT_EQ(std::memcmp(ma.data(), mb.data(), sizeof(double) * 16), 0);
  EXPECT_EQ(ea.inliers, eb.inliers);
}

}  // namespace
