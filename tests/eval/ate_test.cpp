// Association, Umeyama alignment and ATE: against the published reference numbers, Eigen's own
// umeyama, and trajectories with a known similarity and known noise.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <random>

#include "orbis/eval/metrics.hpp"
#include "orbis/util/error.hpp"
#include "test_data.hpp"

namespace {

using orbis::StampedPose;
using orbis::Trajectory;
namespace eval = orbis::eval;

Trajectory timesOnly(const std::vector<double>& times) {
  Trajectory t;
  for (double s : times) t.push_back({s, orbis::SE3d()});
  return t;
}

TEST(Association, NearestFirstOneToOneWithinMaxDt) {
  const Trajectory gt = timesOnly({0.00, 0.10, 0.20, 0.30, 0.40});
  // 0.11 and 0.12 both want 0.10; the nearer (0.11) gets it and 0.12 falls out of range of 0.20.
  const Trajectory est = timesOnly({0.011, 0.11, 0.12, 0.39, 0.70});
  const auto pairs = eval::associateByTime(gt, est, 0.02);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].groundTruth, 0u);
  EXPECT_EQ(pairs[0].estimate, 0u);
  EXPECT_EQ(pairs[1].groundTruth, 1u);
  EXPECT_EQ(pairs[1].estimate, 1u);
  EXPECT_EQ(pairs[2].groundTruth, 4u);
  EXPECT_EQ(pairs[2].estimate, 3u);
  EXPECT_TRUE(eval::associateByTime(gt, est, 0.001).empty());
}

TEST(Umeyama, AgreesWithEigenWithAndWithoutScale) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 3 + trial * 5;
    Eigen::Matrix3Xd source(3, n), target(3, n);
    for (int i = 0; i < n; ++i) {
      source.col(i) = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 2.0;
      target.col(i) =
          Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 3.0;  // unrelated: any answer is a fit
    }
    if (trial % 2 == 0) target = (source.array() * 1.7).matrix();  // and some exact ones
    for (bool withScale : {false, true}) {
      const Eigen::Matrix4d reference = Eigen::umeyama(source, target, withScale);
      const orbis::Sim3d ours = eval::umeyamaAlignment(source, target, withScale);
      EXPECT_LT((ours.matrix() - reference).cwiseAbs().maxCoeff(), 1e-9)
          << "trial " << trial << (withScale ? " sim3" : " se3");
    }
  }
}

TEST(Umeyama, RecoversAKnownSimilarityExactly) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const orbis::Sim3d truth(2.5, orbis::SO3d::exp(Eigen::Vector3d(0.3, -1.2, 0.7)), Eigen::Vector3d(1, -2, 3));
  Eigen::Matrix3Xd source(3, 50), target(3, 50);
  for (int i = 0; i < 50; ++i) {
    source.col(i) = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    target.col(i) = truth * Eigen::Vector3d(source.col(i));
  }
  const orbis::Sim3d found = eval::umeyamaAlignment(source, target, true);
  EXPECT_NEAR(found.scale(), 2.5, 1e-12);
  EXPECT_LT((found.matrix() - truth.matrix()).cwiseAbs().maxCoeff(), 1e-10);
  // Without scale the rotation is still the true one (the scale only stretches).
  EXPECT_LT((eval::umeyamaAlignment(source, target, false).so3().matrix() - truth.so3().matrix()).norm(),
            1e-10);
}

TEST(Ate, ReferenceTrajectoryMatchesThePublishedNumbers) {
  ORBIS_REQUIRE_DATASET(reference, "reference");
  const Trajectory gt =
      orbis::readTrajectory(reference / "freiburg1_xyz-groundtruth.txt", orbis::TrajectoryFormat::Tum);
  const Trajectory est =
      orbis::readTrajectory(reference / "freiburg1_xyz-rgbdslam.txt", orbis::TrajectoryFormat::Tum);
  const eval::AteResult se3 = eval::computeAte(gt, est, {eval::Alignment::SE3, 0.02});
  eval::AteOptions simOptions;
  simOptions.alignment = eval::Alignment::Sim3;
  const eval::AteResult sim3 = eval::computeAte(gt, est, simOptions);
  std::printf("[ reference] ATE SE(3): rmse %.6f m over %zu poses; Sim(3): rmse %.6f m, scale %.6f\n",
              se3.stats.rmse, se3.stats.count, sim3.stats.rmse, sim3.alignment.scale());
  EXPECT_EQ(se3.stats.count, 786u);
  EXPECT_NEAR(se3.stats.rmse, 0.01347, 5e-6);
  EXPECT_EQ(sim3.stats.count, 786u);
  EXPECT_NEAR(sim3.stats.rmse, 0.01339, 5e-6);
  EXPECT_LE(sim3.stats.rmse, se3.stats.rmse);  // one more degree of freedom never fits worse
  EXPECT_LE(se3.stats.median, se3.stats.max);
  EXPECT_LE(se3.stats.mean, se3.stats.rmse);
}

TEST(Ate, GroundTruthAgainstItselfIsZero) {
  ORBIS_REQUIRE_DATASET(reference, "reference");
  const Trajectory gt =
      orbis::readTrajectory(reference / "freiburg1_xyz-groundtruth.txt", orbis::TrajectoryFormat::Tum);
  for (auto alignment : {eval::Alignment::None, eval::Alignment::SE3, eval::Alignment::Sim3}) {
    const eval::AteResult ate = eval::computeAte(gt, gt, {alignment, 0.02});
    EXPECT_EQ(ate.stats.count, gt.size());
    EXPECT_LT(ate.stats.max, 1e-9) << eval::toString(alignment);
  }
}

// A trajectory moved by a known Sim(3) and perturbed by known noise: the alignment undoes the
// Sim(3), and the per-pose errors are the noise.
TEST(Ate, KnownSimilarityAndNoiseComeBack) {
  std::mt19937 rng(2024);
  std::normal_distribution<double> normal(0.0, 1.0);
  Trajectory gt, est;
  const orbis::Sim3d moved(0.4, orbis::SO3d::exp(Eigen::Vector3d(0.5, 0.1, -2.0)),
                           Eigen::Vector3d(10, -3, 1));
  const double sigma = 0.01;
  std::vector<double> noiseNorms;
  for (int i = 0; i < 2000; ++i) {
    const double t = 0.01 * i;
    const Eigen::Vector3d p(3 * std::cos(t), 2 * std::sin(2 * t), 0.5 * t);  // a 3-D curve
    const orbis::SE3d pose(orbis::SO3d::exp(Eigen::Vector3d(0.1 * t, 0.2, -0.05 * t)), p);
    gt.push_back({t, pose});
    const Eigen::Vector3d noise(sigma * normal(rng), sigma * normal(rng), sigma * normal(rng));
    noiseNorms.push_back(noise.norm());
    // est = moved^-1 (gt + noise), timestamps shifted by less than max dt.
    const orbis::SE3d noisy(pose.so3(), p + noise);
    est.push_back({t + 0.003, eval::applySimilarity(moved.inverse(), noisy)});
  }
  eval::AteOptions options;
  options.alignment = eval::Alignment::Sim3;
  options.maxDt = 0.004;
  const eval::AteResult ate = eval::computeAte(gt, est, options);
  ASSERT_EQ(ate.stats.count, gt.size());
  EXPECT_NEAR(ate.alignment.scale(), 0.4, 1e-3 * 0.4);
  EXPECT_LT((ate.alignment.so3().matrix() - moved.so3().matrix()).norm(), 1e-3);
  const eval::ErrorStatistics expected = eval::computeStatistics(noiseNorms);
  std::printf("[ noise    ] injected rmse %.6f m, recovered %.6f m (mean %.6f / %.6f)\n", expected.rmse,
              ate.stats.rmse, expected.mean, ate.stats.mean);
  EXPECT_NEAR(ate.stats.rmse, expected.rmse, 0.01 * expected.rmse);
  EXPECT_NEAR(ate.stats.mean, expected.mean, 0.01 * expected.mean);
  EXPECT_NEAR(ate.stats.median, expected.median, 0.02 * expected.median);
  for (std::size_t i = 0; i < noiseNorms.size(); i += 97)
    EXPECT_NEAR(ate.errors[i], noiseNorms[i], 0.1 * sigma) << "pose " << i;

  // With SE(3) only, the scale cannot be undone: the error is far larger than the noise.
  const eval::AteResult se3 = eval::computeAte(gt, est, {eval::Alignment::SE3, 0.004});
  EXPECT_GT(se3.stats.rmse, 10 * expected.rmse);
}

TEST(Ate, StatisticsAreThoseOfTheErrors) {
  const eval::ErrorStatistics s = eval::computeStatistics({3.0, 1.0, 4.0, 2.0});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(eval::computeStatistics({5.0, 1.0, 3.0}).median, 3.0);
}

TEST(Ate, NoOverlapIsAnError) {
  EXPECT_THROW(eval::computeAte(timesOnly({0, 1, 2}), timesOnly({10, 11}), {}), orbis::Error);
}

}  // namespace
