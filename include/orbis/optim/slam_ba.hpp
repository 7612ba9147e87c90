// orbis/optim/slam_ba.hpp — the bundle adjustments the SLAM pipeline calls (paper §III-C/D):
// motion-only BA on every frame, local BA on every keyframe, full BA after a loop.
//
// Contract: inputs are plain values — poses are camera-from-world SE3d, observations carry the
// measurement (uL, v, uR) with uR < 0 meaning "monocular" (ORB-SLAM's convention) and their
// information 1/σ² (see levelInformation). Camera is the sensor's model, and picks the residual
// at compile time: PinholeCamera (every observation monocular), RectifiedStereoCamera (ORB-SLAM's
// (uL, v, uR) residual) or RgbdCamera (the depth reading as a whitened disparity,
// DisparityReprojection, weighted by 1 / camera.disparitySigma, which must be positive);
// monocular observations of a 3-D model use its pinhole.
// Huber thresholds are the χ² 95% quantiles (5.991 mono, 7.815 stereo). Observations whose χ²
// exceeds them after the robust pass, or whose point is behind the camera, are reported as
// outliers, as ORB-SLAM classifies them. Nothing here throws (except writing the optional BAL
// dump, which throws orbis::Error); a solve stops early when abortFlag is raised.
#pragma once

#include "orbis/io/bal.hpp"
#include "orbis/optim/bal.hpp"
#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"

#include <atomic>
#include <filesystem>
#include <span>
#include <vector>

namespace orbis::optim {

struct SlamObservation {
  int pose = 0;                  // index into the poses (always 0 for motion-only BA)
  int point = 0;                 // index into the points
  Eigen::Vector3d measurement;   // (uL, v, uR); uR < 0: monocular
  double information = 1.0;      // 1/σ², ORB-SLAM: 1/scaleFactor^(2·octave)
  bool isStereo() const { return measurement.z() >= 0.0; }
};

struct MotionOnlyOptions {
  int rounds = 4;
  int iterationsPerRound = 10;
  int robustRounds = 3;  // Huber in the first three rounds, the last one without (ORB-SLAM2)
  // Each round starts again from the prior pose, with the inliers of the round before (ORB-SLAM2):
  // a round that outliers dragged off does not hand its pose on.
  double chi2Mono = kChi2Mono;
  double chi2Stereo = kChi2Stereo;
  bool restartEachRound = true;
};

struct MotionOnlyResult {
  int inliers = 0;
  std::vector<char> outlier;  // per observation
  SolverSummary lastRound;
};

struct BundleAdjustmentOptions {
  int iterations = 5;            // the robust pass (ORB-SLAM local BA: 5; full BA: 10 or 20)
  int refineIterations = 10;     // after removing outliers, without kernel (local BA: 10; 0 = skip)
  double chi2Mono = kChi2Mono;
  double chi2Stereo = kChi2Stereo;
  const std::atomic<bool>* abortFlag = nullptr;
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;
  // When set, the problem is written there in BAL form before solving (for replay with `orbis ba`).
  std::filesystem::path dumpBal;
};

struct BundleAdjustmentResult {
  std::vector<char> outlier;  // per observation, after the last pass
  SolverSummary robustPass;
  SolverSummary refinePass;
};

// The residual of a camera model's 3-D observations: ORB-SLAM's (uL, v, uR) for a stereo pair,
// the whitened disparity for a depth sensor (its uR is uL minus the sensor's disparity).
template <CameraModel Camera>
struct MetricResidualFor {
  using type = Reprojection<Camera>;
};
template <>
struct MetricResidualFor<RgbdCamera<double>> {
  using type = DisparityReprojection<RgbdCamera<double>>;
};
template <CameraModel Camera>
using MetricResidual = typename MetricResidualFor<Camera>::type;

// The problem type a camera model needs: a monocular term, plus a 3-D term for metric cameras.
template <CameraModel Camera>
struct SlamProblemFor {
  using type = Problem<SE3Manifold, Term<MonoReprojection, HuberKernel>, Term<MetricResidual<Camera>, HuberKernel>>;
};
template <>
struct SlamProblemFor<PinholeCamera<double>> {
  using type = Problem<SE3Manifold, Term<MonoReprojection, HuberKernel>>;
};
template <CameraModel Camera>
using SlamProblem = typename SlamProblemFor<Camera>::type;

namespace slam_detail {

template <CameraModel Camera>
const PinholeCamera<double>& pinholeOf(const Camera& camera) {
  if constexpr (requires { camera.pinhole; }) {
    return camera.pinhole;
  } else {
    return camera;
  }
}

// Adds one observation as a mono or stereo residual with its Huber threshold.
template <CameraModel Camera>
ResidualId addObservation(SlamProblem<Camera>& problem, const Camera& camera,
                          const SlamObservation& o, double chi2Mono, double chi2Stereo) {
  if constexpr (Camera::kObservationDim == 3) {
    if (o.isStereo()) {
      using R = MetricResidual<Camera>;
      if constexpr (requires { R::disparityWeight; }) {
        return problem.add(R{o.measurement, &camera, 1.0 / camera.disparitySigma}, o.pose, o.point, o.information,
                           chi2Stereo);
      } else {
        return problem.add(R{o.measurement, &camera}, o.pose, o.point, o.information, chi2Stereo);
      }
    }
  }
  return problem.add(MonoReprojection{o.measurement.head<2>(), &pinholeOf(camera)}, o.pose, o.point,
                     o.information, chi2Mono);
}

// Huber with an infinite threshold is the plain quadratic: how the kernel is removed.
template <class P>
void removeKernels(P& problem) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((
         [&] {
           for (auto& rec : problem.template records<I>()) {
             rec.delta2 = std::numeric_limits<double>::infinity();
           }
         }()),
     ...);
  }(std::make_index_sequence<P::kNumTerms>{});
}

// ORB-SLAM's classification: χ² above the quantile of the observation's dimension, or behind.
template <class P>
bool isOutlier(const P& problem, ResidualId id, const SlamObservation& o, double chi2Mono,
               double chi2Stereo) {
  const double threshold = o.isStereo() && id.term == 1 ? chi2Stereo : chi2Mono;
  if (problem.chi2(id) > threshold) return true;
  return (problem.pose(o.pose) * problem.point(o.point)).z() <= 0.0;
}

}  // namespace slam_detail

// Motion-only BA (tracking): the pose moves, the points stay. Four rounds of ten iterations;
// after each round every observation is re-classified (outliers can come back), and only the
// inliers take part in the next round, which starts again from the prior pose (or continues,
// without restartEachRound).
template <CameraModel Camera>
MotionOnlyResult motionOnlyBundleAdjustment(const Camera& camera, SE3d& cameraFromWorld,
                                            std::span<const Eigen::Vector3d> pointsWorld,
                                            std::span<const SlamObservation> observations,
                                            const MotionOnlyOptions& options = {}) {
  SlamProblem<Camera> problem;
  problem.addPose(cameraFromWorld);
  for (const auto& p : pointsWorld) problem.addPoint(p, /*fixed=*/true);
  std::vector<ResidualId> ids;
  ids.reserve(observations.size());
  for (const auto& o : observations) {
    SlamObservation single = o;
    single.pose = 0;
    ids.push_back(slam_detail::addObservation(problem, camera, single, options.chi2Mono, options.chi2Stereo));
  }
  MotionOnlyResult result;
  result.outlier.assign(observations.size(), 0);
  SolverOptions solver;
  solver.maxIterations = options.iterationsPerRound;
  solver.linearSolver = LinearSolverKind::DenseCholesky;
  const SE3d prior = cameraFromWorld;
  for (int round = 0; round < options.rounds; ++round) {
    if (round == options.robustRounds) slam_detail::removeKernels(problem);
    if (options.restartEachRound) problem.setPose(0, prior);
    result.lastRound = problem.solve(solver);
    result.inliers = 0;
    for (std::size_t k = 0; k < observations.size(); ++k) {
      SlamObservation single = observations[k];
      single.pose = 0;
      // χ² only: a fixed point cannot be "behind" in a way the pose would not already show.
      const double threshold = single.isStereo() && ids[k].term == 1 ? options.chi2Stereo : options.chi2Mono;
      const bool out = problem.chi2(ids[k]) > threshold;
      result.outlier[k] = out;
      problem.setActive(ids[k], !out);
      result.inliers += !out;
    }
    if (result.inliers < 10) break;  // too few to trust another round (ORB-SLAM's guard)
  }
  cameraFromWorld = problem.pose(0);
  return result;
}

// Local or full BA: poses flagged fixed stay fixed (local BA: keyframes that see the local points
// but are not covisible with the current one; full BA: the first keyframe). Runs a robust pass,
// then — unless refineIterations is 0 or the solve was aborted — drops the outliers and refines
// without kernel. Poses and points are updated in place.
template <CameraModel Camera>
BundleAdjustmentResult bundleAdjustment(const Camera& camera, std::vector<SE3d>& cameraFromWorld,
                                        const std::vector<char>& poseFixed,
                                        std::vector<Eigen::Vector3d>& pointsWorld,
                                        std::span<const SlamObservation> observations,
                                        const BundleAdjustmentOptions& options = {}) {
  SlamProblem<Camera> problem;
  for (std::size_t i = 0; i < cameraFromWorld.size(); ++i) {
    problem.addPose(cameraFromWorld[i], i < poseFixed.size() && poseFixed[i]);
  }
  for (const auto& p : pointsWorld) problem.addPoint(p);
  std::vector<ResidualId> ids;
  ids.reserve(observations.size());
  for (const auto& o : observations) {
    ids.push_back(slam_detail::addObservation(problem, camera, o, options.chi2Mono, options.chi2Stereo));
  }
  if (!options.dumpBal.empty()) writeBal(options.dumpBal, exportBal(problem));
  SolverOptions solver;
  solver.maxIterations = options.iterations;
  solver.abortFlag = options.abortFlag;
  solver.linearSolver = options.linearSolver;
  BundleAdjustmentResult result;
  result.robustPass = problem.solve(solver);
  result.outlier.assign(observations.size(), 0);
  auto classify = [&] {
    for (std::size_t k = 0; k < observations.size(); ++k) {
      result.outlier[k] = slam_detail::isOutlier(problem, ids[k], observations[k], options.chi2Mono,
                                                 options.chi2Stereo);
    }
  };
  classify();
  if (options.refineIterations > 0 && result.robustPass.termination != Termination::Aborted) {
    for (std::size_t k = 0; k < observations.size(); ++k) problem.setActive(ids[k], !result.outlier[k]);
    slam_detail::removeKernels(problem);
    solver.maxIterations = options.refineIterations;
    result.refinePass = problem.solve(solver);
    classify();
  }
  for (std::size_t i = 0; i < cameraFromWorld.size(); ++i) cameraFromWorld[i] = problem.pose(static_cast<int>(i));
  for (std::size_t l = 0; l < pointsWorld.size(); ++l) pointsWorld[l] = problem.point(static_cast<int>(l));
  return result;
}

// Full BA after a loop closure (paper §III-D): every keyframe and point, the first keyframe
// fixed, Huber throughout, abortable. ORB-SLAM runs 20 iterations here.
template <CameraModel Camera>
BundleAdjustmentResult fullBundleAdjustment(const Camera& camera, std::vector<SE3d>& cameraFromWorld,
                                            std::vector<Eigen::Vector3d>& pointsWorld,
                                            std::span<const SlamObservation> observations,
                                            int iterations = 20,
                                            const std::atomic<bool>* abortFlag = nullptr) {
  std::vector<char> fixed(cameraFromWorld.size(), 0);
  if (!fixed.empty()) fixed[0] = 1;
  BundleAdjustmentOptions options;
  options.iterations = iterations;
  options.refineIterations = 0;
  options.abortFlag = abortFlag;
  return bundleAdjustment(camera, cameraFromWorld, fixed, pointsWorld, observations, options);
}

}  // namespace orbis::optim
