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
// The robust kernel is a compile-time policy (any RobustKernel: Huber, ORB-SLAM's, by default;
// Cauchy, Tukey or a user's), its thresholds the χ² 95% quantiles (5.991 mono, 7.815 stereo).
// Passes "without kernel" solve the same residuals as terms of TrivialKernel (withoutKernel()),
// so no kernel is ever asked to evaluate an infinite threshold. Observations whose χ² exceeds
// the quantile after the robust pass, or whose point is behind the camera, are reported as
// outliers, as ORB-SLAM classifies them. Nothing here throws; a solve stops early when
// abortFlag is raised.
#pragma once

#include <functional>

#include "orbis/camera/fisheye_plane_camera.hpp"
#include "orbis/optim/bal.hpp"
#include "orbis/optim/pose_only_problem.hpp"
#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"

#include <atomic>
#include <filesystem>
#include <span>
#include <vector>

namespace orbis::optim {

// One keypoint's observation of a map point, as the BA over the map builds it.
struct SlamObservation {
  int pose = 0;                  // index into the poses (always 0 for motion-only BA)
  int point = 0;                 // index into the points
  Eigen::Vector3d measurement;   // (uL, v, uR); uR < 0: monocular
  double information = 1.0;      // 1/σ², ORB-SLAM: 1/scaleFactor^(2·octave)
  // Whether the observation has a right coordinate.
  bool isStereo() const { return measurement.z() >= 0.0; }
};

// ORB-SLAM2's motion-only BA schedule.
struct MotionOnlyOptions {
  // @{
  // Rounds and iterations per round.
  int rounds = 4;
  int iterationsPerRound = 10;
  // @}
  int robustRounds = 3;  // Huber in the first three rounds, the last one without (ORB-SLAM2)
  // Each round starts again from the prior pose, with the inliers of the round before (ORB-SLAM2):
  // a round that outliers dragged off does not hand its pose on.
  double chi2Mono = kChi2Mono;
  // χ² threshold of stereo observations.
  double chi2Stereo = kChi2Stereo;
  // Each round starts from the prior pose.
  bool restartEachRound = true;
};

// The result of a motion-only BA.
struct MotionOnlyResult {
  // Observations within the χ² gates after the last round.
  int inliers = 0;
  std::vector<char> outlier;  // per observation
  // The last round's solver summary.
  SolverSummary lastRound;
};

// Local and full BA settings.
struct BundleAdjustmentOptions {
  int iterations = 5;            // the robust pass (ORB-SLAM local BA: 5; full BA: 10 or 20)
  int refineIterations = 10;     // after removing outliers, without kernel (local BA: 10; 0 = skip)
  // @{
  // χ² thresholds of monocular and stereo observations.
  double chi2Mono = kChi2Mono;
  double chi2Stereo = kChi2Stereo;
  // @}
  // Stops the solve from another thread when set (a new keyframe for local mapping).
  const std::atomic<bool>* abortFlag = nullptr;
  // Dense, sparse or automatic.
  LinearSolverKind linearSolver = LinearSolverKind::Automatic;
  int threads = 1;  // SolverOptions::threads: the same result at any count
  // When set, receives the problem in BAL form before solving (write it with io/bal.hpp's
  // writeBal for replay with `orbis ba`); pinhole and stereo cameras only (BAL has no fisheye).
  std::function<void(const BalProblem&)> inspectBal;
};

// The result of a BA.
struct BundleAdjustmentResult {
  std::vector<char> outlier;  // per observation, after the last pass
  // @{
  // Solver summaries of the robust pass and the refinement.
  SolverSummary robustPass;
  SolverSummary refinePass;
  // @}
};

// The residual of a camera model's 3-D observations: ORB-SLAM's (uL, v, uR) for a stereo pair,
// the whitened disparity for a depth sensor (its uR is uL minus the sensor's disparity).
template <CameraModel Camera>
struct MetricResidualFor {
  // The reprojection residual, for stereo pairs.
  using type = Reprojection<Camera>;
};
// Depth cameras use the disparity residual.
template <>
struct MetricResidualFor<RgbdCamera<double>> {
  // The disparity residual.
  using type = DisparityReprojection<RgbdCamera<double>>;
};
// The residual a camera model's 3-D observations use.
template <CameraModel Camera>
using MetricResidual = typename MetricResidualFor<Camera>::type;

// The residual of a camera model's 2-D observations: the pinhole's, or the lens's for a camera
// that observes through one.
template <CameraModel Camera>
struct MonoResidualFor {
  // The pinhole reprojection.
  using type = MonoReprojection;
};
// Through a lens: the residual in the lens's pixels.
template <ObservesThroughLens Camera>
struct MonoResidualFor<Camera> {
  // The lens's reprojection.
  using type = Reprojection<typename Camera::Lens>;
};
// The residual a camera model's 2-D observations use.
template <CameraModel Camera>
using MonoResidual = typename MonoResidualFor<Camera>::type;

// The problem type a camera model needs: a monocular term, plus a 3-D term for metric cameras,
// each under the robust kernel Kernel.
template <CameraModel Camera, RobustKernel Kernel>
struct SlamProblemFor {
  // A monocular and a metric term.
  using type = Problem<SE3Manifold, Term<MonoReprojection, Kernel>, Term<MetricResidual<Camera>, Kernel>>;
};
// A monocular camera: one term.
template <CameraModel Camera, RobustKernel Kernel>
  requires(Camera::kObservationDim == 2)
struct SlamProblemFor<Camera, Kernel> {
  // The monocular term only.
  using type = Problem<SE3Manifold, Term<MonoResidual<Camera>, Kernel>>;
};
// The problem type of camera model Camera under kernel Kernel.
template <CameraModel Camera, RobustKernel Kernel = HuberKernel>
using SlamProblem = typename SlamProblemFor<Camera, Kernel>::type;

// The motion-only problem of a camera model: SlamProblem's residual types on one free pose.
template <CameraModel Camera, RobustKernel Kernel>
struct MotionOnlyProblemFor {
  // A monocular and a metric residual.
  using type = PoseOnlyProblem<Kernel, MonoReprojection, MetricResidual<Camera>>;
};
// A monocular camera: one residual type.
template <CameraModel Camera, RobustKernel Kernel>
  requires(Camera::kObservationDim == 2)
struct MotionOnlyProblemFor<Camera, Kernel> {
  // The monocular residual only.
  using type = PoseOnlyProblem<Kernel, MonoResidual<Camera>>;
};
// The motion-only problem type of camera model Camera under kernel Kernel.
template <CameraModel Camera, RobustKernel Kernel = HuberKernel>
using MotionOnlyProblem = typename MotionOnlyProblemFor<Camera, Kernel>::type;

// The same problem type with every term's kernel replaced by TrivialKernel.
template <class P>
struct WithoutKernelFor;
// The problem with TrivialKernel in every term.
template <Manifold M, class... Residuals, class... Kernels>
struct WithoutKernelFor<Problem<M, Term<Residuals, Kernels>...>> {
  // The kernel-free problem type.
  using type = Problem<M, Term<Residuals, TrivialKernel>...>;
};

// A copy of `problem` — values, fixed flags, residuals, informations, active flags — whose terms
// carry no kernel: how a pass "without kernel" is run. Residual ids stay valid in the copy.
template <class P>
typename WithoutKernelFor<P>::type withoutKernel(const P& problem) {
  typename WithoutKernelFor<P>::type plain;
  for (int i = 0; i < problem.numPoses(); ++i) plain.addPose(problem.pose(i), problem.poseFixed(i));
  for (int l = 0; l < problem.numPoints(); ++l) plain.addPoint(problem.point(l), problem.pointFixed(l));
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((
         [&] {
           for (const auto& rec : problem.template records<I>()) {
             const ResidualId id = plain.add(rec.residual, rec.pose, rec.other, rec.information);
             if (!rec.active) plain.setActive(id, false);
           }
         }()),
     ...);
  }(std::make_index_sequence<P::kNumTerms>{});
  return plain;
}

namespace slam_detail {

// Adds one observation as a mono or stereo residual with its kernel threshold.
template <CameraModel Camera, class P>
ResidualId addObservation(P& problem, const Camera& camera,
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
  if constexpr (ObservesThroughLens<Camera>) {
    return problem.add(MonoResidual<Camera>{camera.lensPixel(o.measurement.head<2>()), &camera.lens}, o.pose, o.point,
                       o.information, chi2Mono);
  } else {
    return problem.add(MonoReprojection{o.measurement.head<2>(), &pinholeOf(camera)}, o.pose, o.point,
                       o.information, chi2Mono);
  }
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
// without restartEachRound). Rounds from options.robustRounds on run without kernel.
template <RobustKernel Kernel = HuberKernel, CameraModel Camera>
MotionOnlyResult motionOnlyBundleAdjustment(const Camera& camera, SE3d& cameraFromWorld,
                                            std::span<const Eigen::Vector3d> pointsWorld,
                                            std::span<const SlamObservation> observations,
                                            const MotionOnlyOptions& options = {}) {
  // The same bits as SlamProblem<Camera, Kernel> with the points fixed (and withoutKernel() for
  // the last rounds), without rebuilding a sparse structure for each round.
  MotionOnlyProblem<Camera, Kernel> problem(cameraFromWorld, pointsWorld);
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
  // One round; false when too few inliers are left to trust another.
  auto round = [&] {
    if (options.restartEachRound) problem.setPose(prior);
    result.lastRound = problem.solve(solver);
    result.inliers = 0;
    for (std::size_t k = 0; k < observations.size(); ++k) {
      // χ² only: a fixed point cannot be "behind" in a way the pose would not already show.
      const double threshold = observations[k].isStereo() && ids[k].term == 1 ? options.chi2Stereo : options.chi2Mono;
      const bool out = problem.chi2(ids[k]) > threshold;
      result.outlier[k] = out;
      problem.setActive(ids[k], !out);
      result.inliers += !out;
    }
    cameraFromWorld = problem.pose();
    return result.inliers >= 10;  // ORB-SLAM's guard
  };
  bool goOn = true;
  for (int r = 0; r < options.rounds && goOn; ++r) {
    problem.setRobust(r < options.robustRounds);
    goOn = round();
  }
  return result;
}

// Local or full BA: poses flagged fixed stay fixed (local BA: keyframes that see the local points
// but are not covisible with the current one; full BA: the first keyframe). Runs a robust pass,
// then — unless refineIterations is 0 or the solve was aborted — drops the outliers and refines
// without kernel. Poses and points are updated in place.
template <RobustKernel Kernel = HuberKernel, CameraModel Camera>
BundleAdjustmentResult bundleAdjustment(const Camera& camera, std::vector<SE3d>& cameraFromWorld,
                                        const std::vector<char>& poseFixed,
                                        std::vector<Eigen::Vector3d>& pointsWorld,
                                        std::span<const SlamObservation> observations,
                                        const BundleAdjustmentOptions& options = {}) {
  SlamProblem<Camera, Kernel> problem;
  for (std::size_t i = 0; i < cameraFromWorld.size(); ++i) {
    problem.addPose(cameraFromWorld[i], i < poseFixed.size() && poseFixed[i]);
  }
  for (const auto& p : pointsWorld) problem.addPoint(p);
  std::vector<ResidualId> ids;
  ids.reserve(observations.size());
  for (const auto& o : observations) {
    ids.push_back(slam_detail::addObservation(problem, camera, o, options.chi2Mono, options.chi2Stereo));
  }
  if constexpr (!ObservesThroughLens<Camera>) {  // BAL is a pinhole format: lens problems are not exported
    if (options.inspectBal) options.inspectBal(exportBal(problem));
  }
  SolverOptions solver;
  solver.maxIterations = options.iterations;
  solver.abortFlag = options.abortFlag;
  solver.linearSolver = options.linearSolver;
  solver.threads = options.threads;
  BundleAdjustmentResult result;
  result.robustPass = problem.solve(solver);
  result.outlier.assign(observations.size(), 0);
  auto classify = [&](const auto& solved) {
    for (std::size_t k = 0; k < observations.size(); ++k) {
      result.outlier[k] = slam_detail::isOutlier(solved, ids[k], observations[k], options.chi2Mono,
                                                 options.chi2Stereo);
    }
  };
  auto writeBack = [&](const auto& solved) {
    for (std::size_t i = 0; i < cameraFromWorld.size(); ++i) cameraFromWorld[i] = solved.pose(static_cast<int>(i));
    for (std::size_t l = 0; l < pointsWorld.size(); ++l) pointsWorld[l] = solved.point(static_cast<int>(l));
  };
  classify(problem);
  if (options.refineIterations > 0 && result.robustPass.termination != Termination::Aborted) {
    for (std::size_t k = 0; k < observations.size(); ++k) problem.setActive(ids[k], !result.outlier[k]);
    auto plain = withoutKernel(problem);
    solver.maxIterations = options.refineIterations;
    result.refinePass = plain.solve(solver);
    classify(plain);
    writeBack(plain);
  } else {
    writeBack(problem);
  }
  return result;
}

// Full BA after a loop closure (paper §III-D): every keyframe and point, the first keyframe
// fixed, the kernel throughout, abortable. ORB-SLAM runs 20 iterations here.
template <RobustKernel Kernel = HuberKernel, CameraModel Camera>
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
  return bundleAdjustment<Kernel>(camera, cameraFromWorld, fixed, pointsWorld, observations, options);
}

}  // namespace orbis::optim
