// BAL: the 9-parameter camera as a user-defined residual, file round trip and errors, the
// engine solving a synthetic BAL problem, and the export of a SLAM problem to BAL.
#include "jacobian_check.hpp"

#include "orbis/io/bal.hpp"
#include "orbis/optim/bal.hpp"
#include "orbis/util/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace orbis::optim {
namespace {

namespace fs = std::filesystem;

// Cameras on a circle looking inwards (BAL cameras look down −z), points near the centre.
BalProblem syntheticBal(int cameras, int points, double noisePx, unsigned seed, BalProblem* truth) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noisePx);
  BalProblem bal;
  for (int c = 0; c < cameras; ++c) {
    const double a = 0.6 * c / cameras;
    // World-to-camera rotation about y by a, camera 10 m from the origin along its +z.
    BalProblem::Camera cam;
    cam << 0.0, a, 0.0, 0.0, 0.0, -10.0, 800.0 + 20 * u(rng), 1e-3 * u(rng), 1e-5 * u(rng);
    bal.cameras.push_back(cam);
  }
  for (int p = 0; p < points; ++p) bal.points.emplace_back(2 * u(rng), 2 * u(rng), 2 * u(rng));
  for (int c = 0; c < cameras; ++c) {
    for (int p = 0; p < points; ++p) {
      Eigen::Vector2d r;
      BalReprojection{Eigen::Vector2d::Zero()}.evaluate(bal.cameras[c], bal.points[p], r, nullptr, nullptr);
      bal.observations.push_back({c, p, r.x() + noise(rng), r.y() + noise(rng)});
    }
  }
  if (truth) *truth = bal;
  for (auto& cam : bal.cameras) {
    for (int k = 0; k < 6; ++k) cam[k] += 0.01 * u(rng);
  }
  for (auto& p : bal.points) p += 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return bal;
}

TEST(OptimBal, ReprojectionJacobiansMatchNumeric) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    BalProblem::Camera cam;
    cam << 0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng), u(rng), u(rng), -8 + u(rng), 500 + 100 * u(rng),
        0.05 * u(rng), 0.01 * u(rng);
    const Eigen::Vector3d point(u(rng), u(rng), u(rng));
    const auto d = test::checkJacobians(BalReprojection{{10 * u(rng), 10 * u(rng)}}, cam, point);
    worst = std::max(worst, d.relative());
  }
  std::printf("BalReprojection (2x9x3): max relative discrepancy %.3e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

TEST(OptimBal, SolvesSyntheticProblemToNoiseFloor) {
  const double sigma = 0.5;
  BalProblem truth;
  BalProblem bal = syntheticBal(12, 200, sigma, 5, &truth);
  const SolverSummary summary = solveBal(bal, {}, 1.0);
  // At the optimum almost every residual is inside the Huber threshold, so the cost is close to
  // ½·σ²·(m − n); m = 2·observations, n ≈ 3 per point + 9 per camera (minus the 7-dof gauge).
  const double m = 2.0 * bal.observations.size(), n = 3.0 * 200 + 9.0 * 12 - 7;
  const double floor = 0.5 * sigma * sigma * (m - n);
  std::printf("BAL synthetic: cost %.2f -> %.2f (noise floor %.2f) in %d iterations, %s\n",
              summary.initialCost, summary.finalCost, floor, summary.iterations,
              toString(summary.termination));
  EXPECT_TRUE(summary.converged());
  EXPECT_GT(summary.initialCost, 10 * floor);
  EXPECT_NEAR(summary.finalCost, floor, 0.1 * floor);
}

TEST(OptimBal, FileRoundTripAndErrors) {
  BalProblem bal = syntheticBal(3, 10, 0.5, 6, nullptr);
  const fs::path dir = fs::temp_directory_path() / "orbis_bal_test";
  fs::create_directories(dir);
  const fs::path file = dir / "problem-3-10-pre.txt";
  writeBal(file, bal);
  const BalProblem back = readBal(file);
  ASSERT_EQ(back.observations.size(), bal.observations.size());
  for (std::size_t c = 0; c < bal.cameras.size(); ++c) EXPECT_EQ(back.cameras[c], bal.cameras[c]);
  for (std::size_t p = 0; p < bal.points.size(); ++p) EXPECT_EQ(back.points[p], bal.points[p]);
  EXPECT_EQ(back.observations[7].x, bal.observations[7].x);

  const fs::path broken = dir / "broken.txt";
  std::ofstream(broken) << "1 1 2\n0 0 1.0 2.0\n0 5 1.0 2.0\n";
  try {
    readBal(broken);
    FAIL() << "an out-of-range point index must throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("broken.txt"), std::string::npos) << e.what();
    EXPECT_EQ(e.where(), "line 3");
  }
  std::ofstream(broken) << "1 1 1\n0 0 1.0 abc\n";
  EXPECT_THROW(readBal(broken), Error);
  EXPECT_THROW(readBal(dir / "missing.txt"), Error);
  fs::remove_all(dir);
}

TEST(OptimBal, ExportedSlamProblemHasTheSameCost) {
  const PinholeCamera<double> camera{500.0, 500.0, 320.0, 240.0, 640, 480};
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Problem<SE3Manifold, Term<MonoReprojection>> slam;
  for (int c = 0; c < 4; ++c) {
    SE3d::Tangent xi;
    xi << u(rng), u(rng), u(rng), 0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng);
    slam.addPose(SE3d::exp(xi));
  }
  for (int p = 0; p < 30; ++p) {
    const int point = slam.addPoint(Eigen::Vector3d(2 * u(rng), 2 * u(rng), 8 + u(rng)));
    for (int c = 0; c < 4; ++c) {
      slam.add(MonoReprojection{{320 + 100 * u(rng), 240 + 100 * u(rng)}, &camera}, c, point);
    }
  }
  const BalProblem bal = exportBal(slam);
  ASSERT_EQ(bal.observations.size(), 120u);
  // With fx = fy and no kernel the BAL residual is the SLAM residual negated.
  const double balCost = makeBalProblem(bal, 1e9).cost();
  EXPECT_NEAR(balCost, slam.cost(), 1e-9 * slam.cost());
}

}  // namespace
}  // namespace orbis::optim
