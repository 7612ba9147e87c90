// A synthetic SE(3) pose graph: a ring of poses with drifting odometry and one loop edge; the
// optimiser must close the loop.
#include "orbis/optim/pose_graph.hpp"
#include "orbis/optim/pose_graph_residuals.hpp"
#include "orbis/optim/problem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace orbis::optim {
namespace {

// Poses (camera-from-world) around a circle of radius 5 m, looking at its centre.
std::vector<SE3d> ring(int n) {
  std::vector<SE3d> poses;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    SE3d::Tangent xi = SE3d::Tangent::Zero();
    xi[4] = a;
    const SE3d worldFromCamera(SO3d::exp(xi.tail<3>()), Eigen::Vector3d(5 * std::sin(a), 0.1 * k, -5 * std::cos(a)));
    poses.push_back(worldFromCamera.inverse());
  }
  return poses;
}

TEST(OptimPoseGraph, SE3LoopIsClosed) {
  const int n = 24;
  const auto truth = ring(n);
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0.0, 0.02);
  Problem<SE3Manifold, Term<RelativePoseSE3>> problem;
  // Start from dead reckoning with biased, noisy odometry: the error accumulates around the ring.
  SE3d current = truth[0];
  problem.addPose(current, /*fixed=*/true);
  for (int k = 1; k < n; ++k) {
    const SE3d odometry = truth[k - 1] * truth[k].inverse();  // T_{k-1,k} = T_{k-1,w} T_{k,w}⁻¹
    SE3d::Tangent bias;
    for (int c = 0; c < 6; ++c) bias[c] = noise(rng) + 0.01;
    const SE3d measured = SE3d::exp(bias) * odometry;
    current = measured.inverse() * current;  // T_{k,w} = T_{k-1,k}⁻¹ T_{k-1,w}
    problem.addPose(current);
    problem.add(RelativePoseSE3{measured}, k - 1, k);
  }
  const SE3d loop = truth[n - 1] * truth[0].inverse();
  const ResidualId loopEdge = problem.add(RelativePoseSE3{loop}, n - 1, 0, /*information=*/100.0);

  auto worstError = [&] {
    double worst = 0.0;
    for (int k = 0; k < n; ++k) {
      worst = std::max(worst, (problem.pose(k).inverse().translation() - truth[k].inverse().translation()).norm());
    }
    return worst;
  };
  const double loopBefore = std::sqrt(problem.chi2(loopEdge) / 100.0);
  const double errorBefore = worstError();
  const SolverSummary summary = problem.solve();
  const double loopAfter = std::sqrt(problem.chi2(loopEdge) / 100.0);
  const double errorAfter = worstError();
  std::printf("SE3 ring of %d: loop residual %.4f -> %.4f, worst position error %.3f -> %.3f m, "
              "cost %.4g -> %.4g in %d iterations\n", n, loopBefore, loopAfter, errorBefore,
              errorAfter, summary.initialCost, summary.finalCost, summary.iterations);
  EXPECT_TRUE(summary.converged());
  EXPECT_GT(loopBefore, 0.3);
  EXPECT_LT(loopAfter, 0.05 * loopBefore);
  EXPECT_LT(errorAfter, 0.3 * errorBefore);
}

// The same ring through the pipeline's entry point, with the edge list it builds.
TEST(OptimPoseGraph, EssentialGraphEntryPointClosesTheLoop) {
  const int n = 16;
  const auto truth = ring(n);
  std::vector<SE3d> poses{truth[0]};
  std::vector<PoseGraphEdgeSE3> edges;
  SE3d::Tangent bias = SE3d::Tangent::Constant(0.02);
  for (int k = 1; k < n; ++k) {
    const SE3d measured = SE3d::exp(bias) * truth[k - 1] * truth[k].inverse();
    poses.push_back(measured.inverse() * poses.back());
    edges.push_back({k - 1, k, measured, 1.0});
  }
  edges.push_back({n - 1, 0, truth[n - 1] * truth[0].inverse(), 1.0});
  std::vector<char> fixed(n, 0);
  fixed[0] = 1;
  const SE3d first = poses[0];
  const double before = (poses[n - 1].inverse().translation() - truth[n - 1].inverse().translation()).norm();
  const SolverSummary summary = optimizePoseGraph(poses, fixed, edges);
  const double after = (poses[n - 1].inverse().translation() - truth[n - 1].inverse().translation()).norm();
  std::printf("essential graph (SE3, %d poses): last pose error %.3f -> %.3f m\n", n, before, after);
  EXPECT_TRUE(summary.converged());
  EXPECT_LT(after, 0.3 * before);
  EXPECT_EQ(0, std::memcmp(first.unitQuaternion().coeffs().data(), poses[0].unitQuaternion().coeffs().data(), 4 * sizeof(double)));
  EXPECT_EQ(0, std::memcmp(first.translation().data(), poses[0].translation().data(), 3 * sizeof(double)));
}

// Monocular drift: every odometry edge over-estimates the scale by 3%; a loop edge measured at
// the true scale must pull the scale back and close the loop.
TEST(OptimPoseGraph, Sim3LoopCorrectsScaleDrift) {
  const int n = 20;
  const auto truthSE3 = ring(n);
  std::vector<Sim3d> truth;
  for (const auto& t : truthSE3) truth.emplace_back(t);
  std::vector<Sim3d> poses{truth[0]};
  std::vector<PoseGraphEdgeSim3> edges;
  Sim3d::Tangent drift = Sim3d::Tangent::Zero();
  drift[6] = std::log(1.03);
  drift[3] = 0.01;
  for (int k = 1; k < n; ++k) {
    const Sim3d measured = Sim3d::exp(drift) * truth[k - 1] * truth[k].inverse();
    poses.push_back(measured.inverse() * poses.back());
    edges.push_back({k - 1, k, measured, 1.0});
  }
  edges.push_back({n - 1, 0, truth[n - 1] * truth[0].inverse(), 10.0});
  std::vector<char> fixed(n, 0);
  fixed[0] = 1;
  auto loopError = [&] {
    return ((truth[n - 1] * truth[0].inverse()).inverse() * poses[n - 1] * poses[0].inverse()).log().norm();
  };
  auto worstScale = [&] {
    double worst = 0.0;
    for (int k = 0; k < n; ++k) worst = std::max(worst, std::abs(std::log(poses[k].scale())));
    return worst;
  };
  const double loopBefore = loopError(), scaleBefore = worstScale();
  const SolverSummary summary = optimizePoseGraph(poses, fixed, edges);
  const double loopAfter = loopError(), scaleAfter = worstScale();
  std::printf("essential graph (Sim3, %d poses): loop error %.4f -> %.4f, worst |log scale| %.4f -> %.4f, "
              "%d iterations\n", n, loopBefore, loopAfter, scaleBefore, scaleAfter, summary.iterations);
  EXPECT_TRUE(summary.converged());
  EXPECT_LT(loopAfter, 0.1 * loopBefore);
  EXPECT_LT(scaleAfter, 0.5 * scaleBefore);
}

}  // namespace
}  // namespace orbis::optim
