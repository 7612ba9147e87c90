// benchmarks/ba_vs_ceres.cpp — the orbis solver against Ceres Solver on the same problems, in
// the same run: same residuals (Ceres calls the very same analytic evaluate()), same whitening,
// same Huber thresholds, same starting point, same iteration cap and tolerances.
//
// Timed: Solve() only, for both (problem construction is paused), so each side pays for its own
// preprocessing (structure, ordering, symbolic factorisation) but not for the caller's setup.
// The table compares CPU time (both sides single-threaded), which stays meaningful on a shared,
// loaded machine where wall time does not.
// Ceres: SPARSE_SCHUR on SuiteSparse (points eliminated first) for BA, DENSE_NORMAL_CHOLESKY for
// the 6-unknown motion-only problem, Levenberg–Marquardt, one thread. SE(3) poses are a 7-number
// block (quaternion, translation) on a manifold whose update is exp(δ)·T, like ours; the cost
// function returns [J_δ 0] for the block and PlusJacobian is [I; 0], so Ceres sees J_δ exactly.
// After the runs a table prints both times, both final costs and the ratio orbis/Ceres.
// Motion-only problems also run on PoseOnlyProblem (what tracking uses; the same bits as the
// general problem), printed after the table against both.
// ORBIS_BAL_FILE=problem-*.txt adds a real BAL problem.
// ORBIS_BA_THREADS=N (default 1) gives both solvers N threads (orbis: SolverOptions::threads,
// Ceres: num_threads); with N > 1 the table compares wall time instead, since CPU time then sums
// the threads.
#include "ba_problem_generator.hpp"

#include "orbis/io/bal.hpp"
#include "orbis/optim/bal.hpp"
#include "orbis/optim/slam_ba.hpp"

#include <benchmark/benchmark.h>
#include <ceres/ceres.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

namespace {

using namespace orbis;

constexpr int kMaxIterations = 200;
constexpr double kFunctionTolerance = 1e-8;
constexpr double kParameterTolerance = 1e-10;
constexpr double kGradientTolerance = 1e-10;

int solverThreads() {
  static const int threads = [] {
    const char* env = std::getenv("ORBIS_BA_THREADS");
    return env && *env ? std::max(1, std::atoi(env)) : 1;
  }();
  return threads;
}

optim::SolverOptions orbisOptions() {
  optim::SolverOptions o;
  o.maxIterations = kMaxIterations;
  o.functionTolerance = kFunctionTolerance;
  o.parameterTolerance = kParameterTolerance;
  o.gradientTolerance = kGradientTolerance;
  o.threads = solverThreads();
  return o;
}

ceres::Solver::Options ceresOptions(bool schur) {
  ceres::Solver::Options o;
  o.minimizer_type = ceres::TRUST_REGION;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.linear_solver_type = schur ? ceres::SPARSE_SCHUR : ceres::DENSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  o.max_num_iterations = kMaxIterations;
  o.function_tolerance = kFunctionTolerance;
  o.parameter_tolerance = kParameterTolerance;
  o.gradient_tolerance = kGradientTolerance;
  o.num_threads = solverThreads();
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  return o;
}

// ---- Ceres side: the SE(3) block and cost functions wrapping our residuals ----
using PoseBlock = std::array<double, 7>;  // qx qy qz qw tx ty tz

SE3d poseFromBlock(const double* x) {
  return SE3d(Eigen::Quaterniond(x[3], x[0], x[1], x[2]), Eigen::Vector3d(x[4], x[5], x[6]));
}
void poseToBlock(const SE3d& pose, double* x) {
  Eigen::Map<Eigen::Vector4d> rotation(x);
  Eigen::Map<Eigen::Vector3d> translation(x + 4);
  rotation = pose.unitQuaternion().coeffs();
  translation = pose.translation();
}

class SE3LeftManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* out) const override {
    poseToBlock(optim::SE3Manifold::plus(poseFromBlock(x), Eigen::Map<const SE3d::Tangent>(delta)), out);
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> j(jacobian);
    j.setZero();
    j.topRows<6>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* delta) const override {
    Eigen::Map<SE3d::Tangent> out(delta);
    out = (poseFromBlock(y) * poseFromBlock(x).inverse()).log();
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> j(jacobian);
    j.setZero();
    j.leftCols<6>().setIdentity();
    return true;
  }
};

template <class Residual, int PoseAmbient>
class CeresCost final : public ceres::SizedCostFunction<Residual::kDim, PoseAmbient, 3> {
 public:
  static constexpr int R = Residual::kDim;
  static constexpr int D = Residual::PoseManifold::kDim;
  CeresCost(const Residual& residual, double information)
      : residual_(residual), sqrtInformation_(std::sqrt(information)) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    typename Residual::PoseManifold::Value pose;
    if constexpr (PoseAmbient == 7) {
      pose = poseFromBlock(parameters[0]);
    } else {
      pose = Eigen::Map<const typename Residual::PoseManifold::Value>(parameters[0]);
    }
    const Eigen::Map<const Eigen::Vector3d> point(parameters[1]);
    optim::ResidualVector<Residual> r;
    optim::PoseJacobian<Residual> jPose;
    optim::PointJacobian<Residual> jPoint;
    const bool wantPose = jacobians && jacobians[0], wantPoint = jacobians && jacobians[1];
    residual_.evaluate(pose, point, r, wantPose ? &jPose : nullptr, wantPoint ? &jPoint : nullptr);
    Eigen::Map<Eigen::Matrix<double, R, 1>> whitened(residuals);
    whitened = sqrtInformation_ * r;
    if (wantPose) {
      Eigen::Map<Eigen::Matrix<double, R, PoseAmbient, Eigen::RowMajor>> j(jacobians[0]);
      j.template leftCols<D>() = sqrtInformation_ * jPose;
      if constexpr (PoseAmbient > D) j.template rightCols<PoseAmbient - D>().setZero();
    }
    if (wantPoint) {
      Eigen::Map<Eigen::Matrix<double, R, 3, Eigen::RowMajor>> j(jacobians[1]);
      j = sqrtInformation_ * jPoint;
    }
    return true;
  }

 private:
  Residual residual_;
  double sqrtInformation_;
};

struct Outcome {
  double initialCost = 0, finalCost = 0;
  int iterations = 0;
};

// ---- the SLAM problems, both ways ----
Outcome solveOrbis(const bench::SlamScene& scene, bool motionOnly, benchmark::State& state) {
  state.PauseTiming();
  optim::SlamProblem<RectifiedStereoCamera<double>> problem;
  for (std::size_t k = 0; k < scene.initialPoses.size(); ++k) problem.addPose(scene.initialPoses[k], scene.poseFixed[k]);
  for (const auto& p : scene.initialPoints) problem.addPoint(p, motionOnly);
  for (const auto& o : scene.observations) {
    optim::slam_detail::addObservation(problem, scene.camera, o, optim::kChi2Mono, optim::kChi2Stereo);
  }
  state.ResumeTiming();
  const optim::SolverSummary s = problem.solve(orbisOptions());
  return {s.initialCost, s.finalCost, s.iterations};
}

// Motion-only problems as tracking solves them since issue 35: PoseOnlyProblem, the same bits as
// the general problem above with every point fixed.
Outcome solveOrbisPoseOnly(const bench::SlamScene& scene, benchmark::State& state) {
  state.PauseTiming();
  optim::MotionOnlyProblem<RectifiedStereoCamera<double>> problem(scene.initialPoses[0], scene.initialPoints);
  for (const auto& o : scene.observations) {
    optim::slam_detail::addObservation(problem, scene.camera, o, optim::kChi2Mono, optim::kChi2Stereo);
  }
  state.ResumeTiming();
  const optim::SolverSummary s = problem.solve(orbisOptions());
  return {s.initialCost, s.finalCost, s.iterations};
}

Outcome solveCeres(const bench::SlamScene& scene, bool motionOnly, benchmark::State& state) {
  state.PauseTiming();
  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  static SE3LeftManifold manifold;
  static ceres::HuberLoss huberMono(std::sqrt(optim::kChi2Mono)), huberStereo(std::sqrt(optim::kChi2Stereo));
  std::vector<PoseBlock> poses(scene.initialPoses.size());
  std::vector<Eigen::Vector3d> points = scene.initialPoints;
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poseToBlock(scene.initialPoses[k], poses[k].data());
    problem.AddParameterBlock(poses[k].data(), 7, &manifold);
    if (scene.poseFixed[k]) problem.SetParameterBlockConstant(poses[k].data());
    ordering->AddElementToGroup(poses[k].data(), 1);
  }
  for (auto& p : points) {
    problem.AddParameterBlock(p.data(), 3);
    if (motionOnly) problem.SetParameterBlockConstant(p.data());
    ordering->AddElementToGroup(p.data(), 0);
  }
  const auto& pinhole = scene.camera.pinhole;
  for (const auto& o : scene.observations) {
    double* pose = poses[o.pose].data();
    double* point = points[o.point].data();
    if (o.isStereo()) {
      problem.AddResidualBlock(new CeresCost<optim::StereoReprojection, 7>({o.measurement, &scene.camera}, o.information),
                               &huberStereo, pose, point);
    } else {
      problem.AddResidualBlock(new CeresCost<optim::MonoReprojection, 7>({o.measurement.head<2>(), &pinhole}, o.information),
                               &huberMono, pose, point);
    }
  }
  ceres::Solver::Options options = ceresOptions(!motionOnly);
  if (!motionOnly) options.linear_solver_ordering.reset(ordering);
  else delete ordering;
  ceres::Solver::Summary summary;
  state.ResumeTiming();
  ceres::Solve(options, &problem, &summary);
  return {summary.initial_cost, summary.final_cost, static_cast<int>(summary.iterations.size()) - 1};
}

// ---- BAL, both ways ----
Outcome solveOrbisBal(const BalProblem& bal, benchmark::State& state) {
  state.PauseTiming();
  optim::BalBundleProblem problem = optim::makeBalProblem(bal, 1.0);
  state.ResumeTiming();
  const optim::SolverSummary s = problem.solve(orbisOptions());
  return {s.initialCost, s.finalCost, s.iterations};
}

Outcome solveCeresBal(const BalProblem& bal, benchmark::State& state) {
  state.PauseTiming();
  ceres::Problem::Options po;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  static ceres::HuberLoss huber(1.0);
  BalProblem copy = bal;
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (auto& c : copy.cameras) ordering->AddElementToGroup(c.data(), 1);
  for (auto& p : copy.points) ordering->AddElementToGroup(p.data(), 0);
  for (const auto& o : copy.observations) {
    problem.AddResidualBlock(new CeresCost<optim::BalReprojection, 9>({{o.x, o.y}}, 1.0), &huber,
                             copy.cameras[o.camera].data(), copy.points[o.point].data());
  }
  ceres::Solver::Options options = ceresOptions(true);
  options.linear_solver_ordering.reset(ordering);
  ceres::Solver::Summary summary;
  state.ResumeTiming();
  ceres::Solve(options, &problem, &summary);
  return {summary.initial_cost, summary.final_cost, static_cast<int>(summary.iterations.size()) - 1};
}

void report(benchmark::State& state, const Outcome& o) {
  state.counters["initial_cost"] = o.initialCost;
  state.counters["final_cost"] = o.finalCost;
  state.counters["iterations"] = o.iterations;
}

// Synthetic BAL: cameras on an arc around a cloud of points, BAL's own camera model.
BalProblem syntheticBal(int cameras, int points, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  BalProblem bal;
  for (int c = 0; c < cameras; ++c) {
    BalProblem::Camera cam;
    cam << 0.0, 1.2 * c / cameras, 0.0, 0.0, 0.0, -12.0, 700 + 50 * u(rng), -0.05 + 0.01 * u(rng), 0.001 * u(rng);
    bal.cameras.push_back(cam);
  }
  for (int p = 0; p < points; ++p) bal.points.emplace_back(3 * u(rng), 3 * u(rng), 3 * u(rng));
  for (int p = 0; p < points; ++p) {
    const int first = static_cast<int>((u(rng) + 1) * 0.5 * cameras) % cameras;
    const int count = 3 + static_cast<int>((u(rng) + 1) * 3);
    for (int k = 0; k < count; ++k) {
      const int c = (first + k) % cameras;
      Eigen::Vector2d r;
      optim::BalReprojection{Eigen::Vector2d::Zero()}.evaluate(bal.cameras[c], bal.points[p], r, nullptr, nullptr);
      if (u(rng) > 0.95) r += Eigen::Vector2d(30 * u(rng), 30 * u(rng));  // 2.5% gross outliers
      bal.observations.push_back({c, p, r.x() + noise(rng), r.y() + noise(rng)});
    }
  }
  for (auto& cam : bal.cameras) {
    for (int k = 0; k < 6; ++k) cam[k] += 0.005 * u(rng);
  }
  for (auto& p : bal.points) p += 0.03 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return bal;
}

struct Case {
  std::string name;
  bench::SlamScene scene;
  bool motionOnly = false;
};

std::vector<std::unique_ptr<Case>>& cases() {
  static std::vector<std::unique_ptr<Case>> all;
  return all;
}
std::vector<std::pair<std::string, std::unique_ptr<BalProblem>>>& balCases() {
  static std::vector<std::pair<std::string, std::unique_ptr<BalProblem>>> all;
  return all;
}

void addSlamCase(const std::string& name, const bench::SlamSceneSpec& spec) {
  auto c = std::make_unique<Case>();
  c->name = name;
  c->scene = bench::makeSlamScene(spec);
  cases().push_back(std::move(c));
}

void registerAll() {
  for (int n : {300, 1000}) {
    auto c = std::make_unique<Case>();
    c->name = "motion_only_" + std::to_string(n);
    c->scene = bench::makeMotionOnlyScene(n, 0.5, 0.05, 100 + n);
    c->motionOnly = true;
    cases().push_back(std::move(c));
  }
  struct LocalSpec { int keyframes, points; };
  for (const LocalSpec l : {LocalSpec{10, 1500}, LocalSpec{15, 3000}, LocalSpec{20, 5000}}) {
    bench::SlamSceneSpec spec;
    spec.keyframes = l.keyframes;
    spec.points = l.points;
    spec.fixedKeyframes = 3;
    spec.seed = 7 + l.keyframes;
    addSlamCase("local_ba_" + std::to_string(l.keyframes) + "kf_" + std::to_string(l.points) + "pts", spec);
  }
  {
    bench::SlamSceneSpec spec;
    spec.keyframes = 200;
    spec.points = 20000;
    spec.minObservationsPerPoint = 2;
    spec.maxObservationsPerPoint = 10;
    spec.fixedKeyframes = 1;
    spec.keyframeSpacing = 0.5;
    spec.seed = 11;
    addSlamCase("full_ba_200kf_20000pts", spec);
  }
  balCases().emplace_back("bal_synthetic_50cams_5000pts", std::make_unique<BalProblem>(syntheticBal(50, 5000, 3)));
  if (const char* file = std::getenv("ORBIS_BAL_FILE")) {
    balCases().emplace_back(std::string("bal_") + std::filesystem::path(file).stem().string(),
                            std::make_unique<BalProblem>(readBal(file)));
  }

  for (const auto& c : cases()) {
    const Case* p = c.get();
    std::fprintf(stderr, "%s: %zu poses, %zu points, %zu observations\n", p->name.c_str(),
                 p->scene.initialPoses.size(), p->scene.initialPoints.size(), p->scene.observations.size());
    benchmark::RegisterBenchmark(("orbis/" + p->name).c_str(), [p](benchmark::State& state) {
      Outcome o;
      for (auto _ : state) o = solveOrbis(p->scene, p->motionOnly, state);
      report(state, o);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark(("ceres/" + p->name).c_str(), [p](benchmark::State& state) {
      Outcome o;
      for (auto _ : state) o = solveCeres(p->scene, p->motionOnly, state);
      report(state, o);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
    if (p->motionOnly) {
      benchmark::RegisterBenchmark(("pose-only/" + p->name).c_str(), [p](benchmark::State& state) {
        Outcome o;
        for (auto _ : state) o = solveOrbisPoseOnly(p->scene, state);
        report(state, o);
      })->Unit(benchmark::kMillisecond)->UseRealTime();
    }
  }
  for (const auto& [name, bal] : balCases()) {
    const BalProblem* p = bal.get();
    std::fprintf(stderr, "%s: %zu cameras, %zu points, %zu observations\n", name.c_str(), p->cameras.size(),
                 p->points.size(), p->observations.size());
    benchmark::RegisterBenchmark(("orbis/" + name).c_str(), [p](benchmark::State& state) {
      Outcome o;
      for (auto _ : state) o = solveOrbisBal(*p, state);
      report(state, o);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark(("ceres/" + name).c_str(), [p](benchmark::State& state) {
      Outcome o;
      for (auto _ : state) o = solveCeresBal(*p, state);
      report(state, o);
    })->Unit(benchmark::kMillisecond)->UseRealTime();
  }
}

// Collects both sides of every case and prints the comparison table at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
      const std::string name = run.benchmark_name();
      const auto slash = name.find('/');
      auto& row = rows_[name.substr(slash + 1)];
      const std::string solver = name.substr(0, slash);
      Side& side = solver == "orbis" ? row.orbis : solver == "pose-only" ? row.poseOnly : row.ceres;
      side.ms = solverThreads() > 1 ? run.GetAdjustedRealTime() : run.GetAdjustedCPUTime();
      side.finalCost = run.counters.at("final_cost");
      side.iterations = run.counters.at("iterations");
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void printTable() const {
    std::printf("\n%d thread(s), %s time\n", solverThreads(), solverThreads() > 1 ? "wall" : "CPU");
    std::printf("\n%-32s %11s %11s %7s %16s %16s %9s %5s %5s\n", "problem", "orbis [ms]", "ceres [ms]", "ratio",
                "orbis final", "ceres final", "rel diff", "it_o", "it_c");
    for (const auto& [name, row] : rows_) {
      const double rel = std::abs(row.orbis.finalCost - row.ceres.finalCost) /
                         std::max(row.orbis.finalCost, row.ceres.finalCost);
      std::printf("%-32s %11.3f %11.3f %7.3f %16.8g %16.8g %9.2e %5.0f %5.0f\n", name.c_str(), row.orbis.ms,
                  row.ceres.ms, row.orbis.ms / row.ceres.ms, row.orbis.finalCost, row.ceres.finalCost, rel,
                  row.orbis.iterations, row.ceres.iterations);
    }
    // Motion-only problems: the general problem against PoseOnlyProblem (what tracking runs).
    for (const auto& [name, row] : rows_) {
      if (row.poseOnly.ms <= 0) continue;
      std::printf("%-32s pose-only %.4f ms (general problem %.4f ms, ratio %.3f; ceres %.4f ms, ratio %.3f); "
                  "final cost %s the general problem's\n",
                  name.c_str(), row.poseOnly.ms, row.orbis.ms, row.poseOnly.ms / row.orbis.ms, row.ceres.ms,
                  row.poseOnly.ms / row.ceres.ms, row.poseOnly.finalCost == row.orbis.finalCost ? "equal to" : "DIFFERS from");
    }
  }

 private:
  struct Side { double ms = 0, finalCost = 0, iterations = 0; };
  struct Row { Side orbis, ceres, poseOnly; };
  std::map<std::string, Row> rows_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  registerAll();
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.printTable();
  benchmark::Shutdown();
  return 0;
}
