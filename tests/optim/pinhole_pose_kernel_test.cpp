// The vector (four- and eight-lane) pinhole residuals against the one-at-a-time code they replace (the
// reprojection residual, the kernel, whitenAndCorrect and PoseOnlyProblem's sums): the same bits
// for the cost, JᵀJ's upper triangle and the gradient, under Huber (both sides of δ) and no
// kernel, for every count (the remainder is the caller's).
#include "orbis/optim/pinhole_pose_kernel.hpp"

#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/optim/reprojection.hpp"
#include "orbis/optim/residual.hpp"
#include "orbis/optim/robust_kernel.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

namespace orbis::optim {
namespace {

struct Sums {
  double cost = 0.0;
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
};

// The one-at-a-time code, residual k.
void addOne(const SE3d& pose, const PinholeCamera<double>& camera, const detail::PinholeResiduals& in, std::size_t k,
            bool huber, Sums& sums) {
  const MonoReprojection residual{Eigen::Vector2d(in.u[k], in.v[k]), &camera};
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> j;
  residual.evaluate(pose, Eigen::Vector3d(in.x[k], in.y[k], in.z[k]), r, &j, nullptr);
  const double s = in.information[k] * r.squaredNorm();
  const KernelValue kv = huber ? HuberKernel::evaluate(s, in.delta2[k]) : TrivialKernel::evaluate(s, in.delta2[k]);
  sums.cost += 0.5 * kv.rho;
  whitenAndCorrect(in.information[k], kv, s, r, &j);
  for (int c = 0; c < 6; ++c)
    for (int row = 0; row <= c; ++row) sums.hessian(row, c) += j(0, row) * j(0, c) + j(1, row) * j(1, c);
  sums.gradient.noalias() -= j.transpose() * r;
}

bool sameBits(const Sums& a, const Sums& b) {
  return std::memcmp(&a.cost, &b.cost, sizeof(double)) == 0 &&
         std::memcmp(a.hessian.data(), b.hessian.data(), sizeof(double) * 36) == 0 &&
         std::memcmp(a.gradient.data(), b.gradient.data(), sizeof(double) * 6) == 0;
}

class PinholePoseKernel : public ::testing::TestWithParam<int> {};

TEST_P(PinholePoseKernel, GivesTheOneAtATimeBits) {
  const int lanes = GetParam();
  if (!detail::pinholePoseKernelAvailable(lanes)) GTEST_SKIP() << "no " << lanes << "-lane build or CPU";
  PinholeCamera<double> camera;
  camera.fx = 535.4;
  camera.fy = 539.2;
  camera.cx = 320.1;
  camera.cy = 247.6;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), depth(0.5, 8.0);
  const SE3d pose = SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.1, -0.2, 0.05, 0.3, -0.1, 0.2).finished());
  const detail::PinholePose p{{pose.unitQuaternion().x(), pose.unitQuaternion().y(), pose.unitQuaternion().z(),
                               pose.unitQuaternion().w()},
                              {pose.translation().x(), pose.translation().y(), pose.translation().z()},
                              camera.fx, camera.fy, camera.cx, camera.cy};
  int outside = 0, compared = 0;
  for (std::size_t n = 0; n <= 41; ++n) {
    detail::PinholeResiduals in;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d pc(unit(rng) * 2, unit(rng) * 1.5, depth(rng));
      const Eigen::Vector3d pw = pose.inverse() * pc;
      const Eigen::Vector2d px = camera.project(pc) + Eigen::Vector2d(unit(rng), unit(rng)) * (k % 3 == 0 ? 15.0 : 1.0);
      in.push(pw.data(), px.data(), 1.0 / (1.0 + static_cast<double>(k % 5)), 5.991, static_cast<int>(k));
    }
    for (const bool huber : {true, false}) {
      Sums vector, one;
      const std::size_t taken = detail::linearizePinholeBlocks(p, in, huber, vector.cost, vector.hessian.data(),
                                                               vector.gradient.data(), lanes);
      ASSERT_EQ(taken, n / static_cast<std::size_t>(lanes) * static_cast<std::size_t>(lanes));
      for (std::size_t k = 0; k < taken; ++k) {
        addOne(pose, camera, in, k, huber, one);
        const Eigen::Vector2d r = camera.project(pose * Eigen::Vector3d(in.x[k], in.y[k], in.z[k])) -
                                  Eigen::Vector2d(in.u[k], in.v[k]);
        outside += huber && in.information[k] * r.squaredNorm() > in.delta2[k];
      }
      EXPECT_TRUE(sameBits(vector, one)) << n << " residuals, huber " << huber;
      double costOnly = 0.0;
      EXPECT_EQ(detail::costPinholeBlocks(p, in, huber, costOnly, lanes), taken);
      EXPECT_EQ(std::memcmp(&costOnly, &one.cost, sizeof(double)), 0) << n << " residuals, huber " << huber;
      ++compared;
    }
  }
  EXPECT_GT(outside, 50);  // Huber's linear side was exercised
  EXPECT_EQ(compared, 84);
}

INSTANTIATE_TEST_SUITE_P(Lanes, PinholePoseKernel, ::testing::Values(4, 8));

}  // namespace
}  // namespace orbis::optim
