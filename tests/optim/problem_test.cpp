// The sparse LM engine on a user-defined residual: convergence to the noise floor, fixed
// variables, robust kernels, dense vs sparse linear solvers, early abort.
#include "jacobian_check.hpp"
#include "test_scenes.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>

namespace orbis::optim {
namespace {

using test::TranslatingCameraResidual;

template <class Kernel>
using TranslatingProblem = Problem<EuclideanManifold<3>, Term<TranslatingCameraResidual, Kernel>>;

// Two cameras fixed (removes the translation/scale gauge), the rest and all points perturbed.
template <class Kernel>
TranslatingProblem<Kernel> buildProblem(const test::TranslatingScene& scene, unsigned seed,
                                        double delta2 = 5.991) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> perturb(0.0, 0.05);
  TranslatingProblem<Kernel> problem;
  for (std::size_t c = 0; c < scene.centres.size(); ++c) {
    const bool fixed = c < 2;
    Eigen::Vector3d start = scene.centres[c];
    if (!fixed) start += Eigen::Vector3d(perturb(rng), perturb(rng), perturb(rng));
    problem.addPose(start, fixed);
  }
  for (const auto& p : scene.points) {
    problem.addPoint(p + Eigen::Vector3d(perturb(rng), perturb(rng), perturb(rng)));
  }
  for (const auto& o : scene.observations) {
    problem.add(TranslatingCameraResidual{o.pixel, 500.0}, o.camera, o.point, 1.0, delta2);
  }
  return problem;
}

double rmsReprojection(const TranslatingProblem<TrivialKernel>& problem) {
  const auto& records = problem.records<0>();
  double sum = 0.0;
  for (std::size_t e = 0; e < records.size(); ++e) sum += problem.chi2({0, static_cast<int>(e)});
  return std::sqrt(sum / (2.0 * static_cast<double>(records.size())));
}

TEST(OptimProblem, TranslatingResidualJacobianMatchesNumeric) {
  const TranslatingCameraResidual residual{{12.0, -7.0}, 480.0};
  const auto d = test::checkJacobians(residual, Eigen::Vector3d(0.2, -0.1, 0.3),
                                      Eigen::Vector3d(1.0, 0.5, 5.0));
  std::printf("translating camera: max |analytic - numeric| = %.3e\n", d.maxAbsError);
  EXPECT_LT(d.relative(), 1e-6);
}

TEST(OptimProblem, ConvergesToNoiseFloor) {
  const double sigma = 0.7;
  const auto scene = test::makeTranslatingScene(8, 150, sigma, 0.0, 7);
  auto problem = buildProblem<TrivialKernel>(scene, 11);
  const double before = rmsReprojection(problem);
  const SolverSummary summary = problem.solve();
  const double after = rmsReprojection(problem);
  std::printf("noise sigma %.3f px: RMS %.3f -> %.3f px in %d iterations (%s)\n", sigma, before,
              after, summary.iterations, toString(summary.termination));
  EXPECT_TRUE(summary.converged());
  EXPECT_GT(before, 5 * sigma);
  // Least squares absorbs one noise degree of freedom per free parameter: E[RMS²] = σ²(m − n)/m.
  const double m = 2.0 * scene.observations.size(), n = 3.0 * (150 + 6);
  const double floor = sigma * std::sqrt((m - n) / m);
  std::printf("expected noise floor %.3f px\n", floor);
  EXPECT_NEAR(after, floor, 0.05 * sigma);
  EXPECT_LT(summary.finalCost, summary.initialCost);
  EXPECT_NEAR(summary.finalCost, problem.cost(), 1e-9 * summary.finalCost);
}

TEST(OptimProblem, FixedVariablesUntouchedBitForBit) {
  const auto scene = test::makeTranslatingScene(6, 60, 0.5, 0.0, 3);
  auto problem = buildProblem<TrivialKernel>(scene, 5);
  problem.setPointFixed(7, true);
  problem.setPointFixed(31, true);
  const Eigen::Vector3d fixedPose0 = problem.pose(0), fixedPose1 = problem.pose(1);
  const Eigen::Vector3d fixedPoint7 = problem.point(7), fixedPoint31 = problem.point(31);
  const Eigen::Vector3d freePose = problem.pose(3);
  problem.solve();
  EXPECT_EQ(0, std::memcmp(fixedPose0.data(), problem.pose(0).data(), sizeof(double) * 3));
  EXPECT_EQ(0, std::memcmp(fixedPose1.data(), problem.pose(1).data(), sizeof(double) * 3));
  EXPECT_EQ(0, std::memcmp(fixedPoint7.data(), problem.point(7).data(), sizeof(double) * 3));
  EXPECT_EQ(0, std::memcmp(fixedPoint31.data(), problem.point(31).data(), sizeof(double) * 3));
  EXPECT_GT((freePose - problem.pose(3)).norm(), 1e-3);  // the free ones did move
}

TEST(OptimProblem, DenseAndSparseSolversAgree) {
  const auto scene = test::makeTranslatingScene(10, 80, 0.5, 0.0, 21);
  auto dense = buildProblem<HuberKernel>(scene, 2);
  auto sparse = buildProblem<HuberKernel>(scene, 2);
  SolverOptions options;
  options.linearSolver = LinearSolverKind::DenseCholesky;
  const auto denseSummary = dense.solve(options);
  options.linearSolver = LinearSolverKind::SparseCholesky;
  const auto sparseSummary = sparse.solve(options);
  EXPECT_FALSE(denseSummary.usedSparseSolver);
  EXPECT_TRUE(sparseSummary.usedSparseSolver);
  EXPECT_EQ(denseSummary.iterations, sparseSummary.iterations);
  EXPECT_NEAR(denseSummary.finalCost, sparseSummary.finalCost, 1e-9 * denseSummary.finalCost);
  for (int c = 0; c < dense.numPoses(); ++c) {
    EXPECT_LT((dense.pose(c) - sparse.pose(c)).norm(), 1e-8);
  }
}

// Robust kernels: with 10% gross outliers, every kernel must give the outliers a smaller weight
// than the inliers and recover the cameras far better than plain least squares.
template <class Kernel>
class OptimKernelTest : public ::testing::Test {};
using Kernels = ::testing::Types<HuberKernel, CauchyKernel, TukeyKernel>;
TYPED_TEST_SUITE(OptimKernelTest, Kernels);

template <class Kernel>
double cameraError(const TranslatingProblem<Kernel>& problem, const test::TranslatingScene& scene) {
  double worst = 0.0;
  for (int c = 0; c < problem.numPoses(); ++c) {
    worst = std::max(worst, (problem.pose(c) - scene.centres[c]).norm());
  }
  return worst;
}

TYPED_TEST(OptimKernelTest, OutliersAreDownWeighted) {
  const auto scene = test::makeTranslatingScene(8, 120, 0.5, 0.1, 99);
  auto plain = buildProblem<TrivialKernel>(scene, 4);
  auto robust = buildProblem<TypeParam>(scene, 4);
  plain.solve();
  const SolverSummary summary = robust.solve();
  const double plainError = cameraError(plain, scene), robustError = cameraError(robust, scene);
  double outlierWeight = 0.0, inlierWeight = 0.0;
  int outliers = 0, inliers = 0;
  for (std::size_t e = 0; e < scene.observations.size(); ++e) {
    const double s = robust.chi2({0, static_cast<int>(e)});
    const double w = TypeParam::evaluate(s, 5.991).rho1;
    if (scene.observations[e].outlier) { outlierWeight += w; ++outliers; }
    else { inlierWeight += w; ++inliers; }
  }
  outlierWeight /= outliers;
  inlierWeight /= inliers;
  std::printf("%s: worst camera error %.4f m (plain LS %.4f m); mean weight outliers %.3f, inliers %.3f\n",
              TypeParam::kName, robustError, plainError, outlierWeight, inlierWeight);
  EXPECT_TRUE(summary.converged());
  EXPECT_LT(outlierWeight, 0.2);
  EXPECT_GT(inlierWeight, 0.5);
  EXPECT_LT(robustError, 0.25 * plainError);
}

TEST(OptimKernels, DerivativesMatchNumeric) {
  const double delta2 = 5.991, h = 1e-5;
  auto check = [&](auto kernel, double s) {
    using K = decltype(kernel);
    const KernelValue k = K::evaluate(s, delta2);
    const double d1 = (K::evaluate(s + h, delta2).rho - K::evaluate(s - h, delta2).rho) / (2 * h);
    const double d2 = (K::evaluate(s + h, delta2).rho1 - K::evaluate(s - h, delta2).rho1) / (2 * h);
    EXPECT_NEAR(k.rho1, d1, 1e-6) << K::kName << " s=" << s;
    EXPECT_NEAR(k.rho2, d2, 1e-6) << K::kName << " s=" << s;
  };
  for (double s : {0.5, 3.0, 9.0, 40.0}) {
    check(TrivialKernel{}, s);
    check(HuberKernel{}, s);
    check(CauchyKernel{}, s);
    check(TukeyKernel{}, s);
  }
}

// Stands in for "another thread": the flag is raised from inside the solve after a few
// residual evaluations, so the abort point is deterministic.
struct AbortingResidual : TranslatingCameraResidual {
  std::atomic<bool>* flag = nullptr;
  int* evaluations = nullptr;
  int abortAfter = 0;
  void evaluate(const Eigen::Vector3d& c, const Eigen::Vector3d& p, Eigen::Vector2d& r,
                Eigen::Matrix<double, 2, 3>* jc, Eigen::Matrix<double, 2, 3>* jp) const {
    if (++*evaluations == abortAfter) flag->store(true);
    TranslatingCameraResidual::evaluate(c, p, r, jc, jp);
  }
};

TEST(OptimProblem, EarlyAbortStopsWithBestParameters) {
  const auto scene = test::makeTranslatingScene(6, 50, 0.5, 0.0, 8);
  std::atomic<bool> abort{false};
  int evaluations = 0;
  Problem<EuclideanManifold<3>, Term<AbortingResidual>> problem;
  for (std::size_t c = 0; c < scene.centres.size(); ++c) {
    problem.addPose(scene.centres[c] + Eigen::Vector3d(0.1, -0.05, 0.08) * (c >= 2), c < 2);
  }
  for (const auto& p : scene.points) problem.addPoint(p + Eigen::Vector3d(0.1, 0.1, -0.2));
  const int perPass = static_cast<int>(scene.observations.size());
  for (const auto& o : scene.observations) {
    AbortingResidual r;
    r.measurement = o.pixel;
    r.flag = &abort;
    r.evaluations = &evaluations;
    r.abortAfter = 3 * perPass;  // during the second linearisation
    problem.add(r, o.camera, o.point);
  }
  SolverOptions options;
  options.abortFlag = &abort;
  const SolverSummary summary = problem.solve(options);
  EXPECT_EQ(summary.termination, Termination::Aborted);
  EXPECT_LE(summary.iterations, 2);
  EXPECT_LT(summary.finalCost, summary.initialCost);
  EXPECT_NEAR(problem.cost(), summary.finalCost, 1e-9 * summary.finalCost);

  // Raised before the solve starts: nothing moves.
  const Eigen::Vector3d before = problem.pose(4);
  const SolverSummary second = problem.solve(options);
  EXPECT_EQ(second.termination, Termination::Aborted);
  EXPECT_EQ(second.iterations, 0);
  EXPECT_EQ(before, problem.pose(4));
}

}  // namespace
}  // namespace orbis::optim
