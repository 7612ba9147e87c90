// orbis/optim/problem.hpp — a sparse least-squares problem over poses and 3-D points, solved by
// Levenberg–Marquardt with the points eliminated by a Schur complement.
//
// Contract: Problem<PoseManifold, Term...> stores poses (on PoseManifold), points (R³) and, for
// each Term, residual records of one compile-time residual type and robust kernel. Any pose or
// point may be fixed; fixed values are never written. Residual records can be deactivated (outlier
// rejection) between solves. solve() builds the block structure once, then per iteration
// linearises with the analytic Jacobians, forms the reduced camera system
// S = H_pp − H_pl H_ll⁻¹ H_lp (dense LLT for small systems, CHOLMOD supernodal otherwise) and
// back-substitutes the points. Costs use Ceres' convention ½Σρ(information·‖r‖²).
// Not thread-safe; a solve can be aborted through SolverOptions::abortFlag. SolverOptions::threads
// shares the Schur complement, the back-substitution and the cost between threads without
// changing a bit of the result (problem_impl.hpp says how).
#pragma once

#include "orbis/optim/levenberg_marquardt.hpp"
#include "orbis/optim/reduced_system.hpp"
#include "orbis/optim/residual.hpp"
#include "orbis/util/parallel_for.hpp"

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace orbis::optim {

// A sparse bundle-adjustment problem: poses on manifold PoseM, 3-D points, and residual terms whose
// types and kernels are fixed at compile time; points are eliminated by a Schur complement.
template <Manifold PoseM, class... Terms>
class Problem {
  static_assert(sizeof...(Terms) > 0, "a problem needs at least one residual term");
  static_assert((std::is_same_v<typename Terms::Residual::PoseManifold, PoseM> && ...),
                "every residual must be written against the problem's pose manifold");

 public:
  // @{
  // The pose type and size, the number of terms, and the term and residual types by index.
  using Pose = typename PoseM::Value;
  static constexpr int kPoseDim = PoseM::kDim;
  static constexpr std::size_t kNumTerms = sizeof...(Terms);
  template <std::size_t I>
  using TermAt = std::tuple_element_t<I, std::tuple<Terms...>>;
  template <std::size_t I>
  using ResidualAt = typename TermAt<I>::Residual;
  // @}

  // Adds a pose (fixed: held constant); returns its index.
  int addPose(const Pose& pose, bool fixed = false) {
    poses_.push_back(pose);
    poseFixed_.push_back(fixed);
    return static_cast<int>(poses_.size()) - 1;
  }
  // Adds a point (fixed: held constant); returns its index.
  int addPoint(const Eigen::Vector3d& point, bool fixed = false) {
    points_.push_back(point);
    pointFixed_.push_back(fixed);
    return static_cast<int>(points_.size()) - 1;
  }
  // other: the point of a PointResidual, pose j of a PoseResidual. delta2: kernel threshold δ².
  template <ResidualBlock R>
  ResidualId add(const R& residual, int pose, int other, double information = 1.0,
                 double delta2 = std::numeric_limits<double>::infinity()) {
    constexpr int term = termOf<R>();
    static_assert(term >= 0, "residual type is not one of the problem's terms");
    auto& records = std::get<term>(records_);
    records.push_back(ResidualRecord<R>{residual, pose, other, information, delta2, true});
    return {term, static_cast<int>(records.size()) - 1};
  }

  // @{
  // Poses and points: counts, values and fixed flags, read and set.
  int numPoses() const { return static_cast<int>(poses_.size()); }
  int numPoints() const { return static_cast<int>(points_.size()); }
  const Pose& pose(int i) const { return poses_[i]; }
  void setPose(int i, const Pose& pose) { poses_[i] = pose; }
  const Eigen::Vector3d& point(int i) const { return points_[i]; }
  void setPoint(int i, const Eigen::Vector3d& point) { points_[i] = point; }
  bool poseFixed(int i) const { return poseFixed_[i] != 0; }
  bool pointFixed(int i) const { return pointFixed_[i] != 0; }
  void setPoseFixed(int i, bool fixed) { poseFixed_[i] = fixed; }
  void setPointFixed(int i, bool fixed) { pointFixed_[i] = fixed; }
  // @}

  // @{
  // The stored residual blocks of term I.
  template <std::size_t I>
  const AlignedVector<ResidualRecord<ResidualAt<I>>>& records() const {
    return std::get<I>(records_);
  }
  template <std::size_t I>
  AlignedVector<ResidualRecord<ResidualAt<I>>>& records() {
    return std::get<I>(records_);
  }
  // @}

  // Switches a residual on or off (outliers are switched off).
  void setActive(ResidualId id, bool active) {
    visitTerm(id.term, [&](auto& records) { records[id.index].active = active; });
  }
  // The robust kernel's threshold δ² of one residual; infinity turns the kernel off.
  void setKernelThreshold(ResidualId id, double delta2) {
    visitTerm(id.term, [&](auto& records) { records[id.index].delta2 = delta2; });
  }
  // Whether a residual is on.
  bool active(ResidualId id) const {
    bool result = false;
    visitTerm(id.term, [&](const auto& records) { result = records[id.index].active; });
    return result;
  }
  // information·‖r‖² at the current values: the statistic ORB-SLAM compares with χ² quantiles.
  double chi2(ResidualId id) const {
    double result = 0.0;
    visitTerm(id.term, [&](const auto& records) {
      const auto& rec = records[id.index];
      result = rec.information * rawResidual(rec, poses_, points_).squaredNorm();
    });
    return result;
  }
  // ½Σρ over active residuals at the current values.
  double cost() const { return evaluateCost(poses_, points_); }

  // Solves by Levenberg–Marquardt from the current values, which it updates.
  SolverSummary solve(const SolverOptions& options = {}) {
    prepare(options);
    SolverSummary summary = levenbergMarquardt(*this, options);
    summary.usedSparseSolver = system_.usesSparse();
    return summary;
  }

  // ---- LinearizedModel interface (used by levenbergMarquardt) ----
  // Whether any pose or point is free (the LinearizedModel interface levenbergMarquardt drives,
  // from here on).
  bool hasFreeVariables() const { return !freePoseIds_.empty() || !freePointIds_.empty(); }
  // Evaluates residuals and Jacobians at the current values and builds the normal equations;
  // returns the cost. On several threads when the problem has only point residuals: same bits.
  double linearize() {
    if constexpr (kOnlyPointResiduals) {
      if (threads_ > 1) return linearizeInParallel();
    }
    return linearizeSerially();
  }
  // The largest gradient entry.
  double maxGradient() const {
    double g = 0.0;
    if (poseRhs_.size() > 0) g = poseRhs_.cwiseAbs().maxCoeff();
    for (const auto& b : pointRhs_) g = std::max(g, b.cwiseAbs().maxCoeff());
    return g;
  }
  // Solves the damped system for a step; false when it failed numerically.
  bool solveDamped(double mu, double& predictedDecrease, double& stepNorm);
  // Norm of the current parameters.
  double parameterNorm() const {
    double sq = 0.0;
    for (int p : freePoseIds_) sq += PoseM::squaredNorm(poses_[p]);
    for (int l : freePointIds_) sq += points_[l].squaredNorm();
    return std::sqrt(sq);
  }
  // Cost at the current values plus the last step.
  double candidateCost() {
    for (std::size_t k = 0; k < freePoseIds_.size(); ++k) {
      const int p = freePoseIds_[k];
      candidatePoses_[p] = PoseM::plus(poses_[p], poseStep_.template segment<kPoseDim>(k * kPoseDim));
    }
    for (std::size_t k = 0; k < freePointIds_.size(); ++k) {
      const int l = freePointIds_[k];
      candidatePoints_[l] = points_[l] + pointStep_[k];
    }
    return threads_ > 1 ? evaluateCostInParallel(candidatePoses_, candidatePoints_)
                        : evaluateCost(candidatePoses_, candidatePoints_);
  }
  // Makes the last step the current values.
  void acceptCandidate() {
    // Only free entries differ between the two arrays, so swapping keeps fixed values intact.
    std::swap(poses_, candidatePoses_);
    std::swap(points_, candidatePoints_);
  }

 private:
  using PoseBlock = Eigen::Matrix<double, kPoseDim, kPoseDim>;
  using CrossBlock = Eigen::Matrix<double, kPoseDim, 3>;
  using PoseVector = Eigen::Matrix<double, kPoseDim, 1>;

  // A (free pose, free point) observation inside the Schur complement.
  struct Link {
    int pose;  // free pose index
    int term;
    int index;
  };

  template <class R, std::size_t... I>
  static constexpr int termOfImpl(std::index_sequence<I...>) {
    int found = -1;
    ((found < 0 && std::is_same_v<R, ResidualAt<I>> ? (found = static_cast<int>(I)) : 0), ...);
    return found;
  }
  template <class R>
  static constexpr int termOf() {
    return termOfImpl<R>(std::index_sequence_for<Terms...>{});
  }
  template <class F>
  static void forEachTerm(F&& f) {
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (f.template operator()<I>(), ...);
    }(std::index_sequence_for<Terms...>{});
  }
  template <class F>
  void visitTerm(int term, F&& f) {
    forEachTerm([&]<std::size_t I>() { if (static_cast<int>(I) == term) f(std::get<I>(records_)); });
  }
  template <class F>
  void visitTerm(int term, F&& f) const {
    forEachTerm([&]<std::size_t I>() { if (static_cast<int>(I) == term) f(std::get<I>(records_)); });
  }

  template <class R>
  static ResidualVector<R> rawResidual(const ResidualRecord<R>& rec, const AlignedVector<Pose>& poses,
                                       const AlignedVector<Eigen::Vector3d>& points) {
    ResidualVector<R> r;
    if constexpr (PointResidual<R>) {
      rec.residual.evaluate(poses[rec.pose], points[rec.other], r, nullptr, nullptr);
    } else {
      rec.residual.evaluate(poses[rec.pose], poses[rec.other], r, nullptr, nullptr);
    }
    return r;
  }

  double evaluateCost(const AlignedVector<Pose>& poses,
                      const AlignedVector<Eigen::Vector3d>& points) const {
    double cost = 0.0;
    forEachTerm([&]<std::size_t I>() {
      using Kernel = typename TermAt<I>::Kernel;
      for (const auto& rec : std::get<I>(records_)) {
        if (!rec.active) continue;
        const double s = rec.information * rawResidual(rec, poses, points).squaredNorm();
        cost += 0.5 * Kernel::evaluate(s, rec.delta2).rho;
      }
    });
    return cost;
  }

  // f(e) for every record index e < count, in chunks of kRecordsPerTask records shared between
  // the threads; f writes only what belongs to record e, so the order of chunks does not matter.
  template <class F>
  void forEachRecordInParallel(std::size_t count, F&& f) {
    const int chunks = static_cast<int>((count + kRecordsPerTask - 1) / kRecordsPerTask);
    parallelFor(threads_, chunks, [&](int chunk) {
      const std::size_t first = static_cast<std::size_t>(chunk) * kRecordsPerTask;
      const std::size_t last = std::min(count, first + kRecordsPerTask);
      for (std::size_t e = first; e < last; ++e) f(e);
    });
  }

  // evaluateCost with the kernel values computed in chunks of records on several threads and
  // summed in record order afterwards: the same cost to the last bit.
  double evaluateCostInParallel(const AlignedVector<Pose>& poses, const AlignedVector<Eigen::Vector3d>& points) {
    double cost = 0.0;
    forEachTerm([&]<std::size_t I>() {
      using Kernel = typename TermAt<I>::Kernel;
      const auto& records = std::get<I>(records_);
      std::vector<double>& rho = recordRho_[I];
      rho.resize(records.size());
      forEachRecordInParallel(records.size(), [&](std::size_t e) {
        const auto& rec = records[e];
        if (!rec.active) return;
        const double s = rec.information * rawResidual(rec, poses, points).squaredNorm();
        rho[e] = Kernel::evaluate(s, rec.delta2).rho;
      });
      for (std::size_t e = 0; e < records.size(); ++e)
        if (records[e].active) cost += 0.5 * rho[e];
    });
    return cost;
  }

  void prepare(const SolverOptions& options);
  double linearizeSerially();
  double linearizeInParallel();
  void assignColumnOwners(int owners);
  void schurComplement(double mu, Eigen::VectorXd& rhs);

  static constexpr std::size_t kRecordsPerTask = 1024;
  static constexpr int kPointsPerTask = 256;
  // Below this many point pairs a Schur complement is too small to share: waking a helper
  // would cost more than it saves.
  static constexpr std::size_t kMinPairsForThreads = 4096;

  AlignedVector<Pose> poses_;
  std::vector<char> poseFixed_;
  AlignedVector<Eigen::Vector3d> points_;
  std::vector<char> pointFixed_;
  std::tuple<AlignedVector<ResidualRecord<typename Terms::Residual>>...> records_;

  // ---- solver state, rebuilt by prepare() ----
  std::vector<int> freePose_, freePoseIds_, freePoint_, freePointIds_;
  std::vector<int> linkStart_;  // per free point, into links_
  std::vector<Link> links_;
  std::array<std::vector<int>, kNumTerms> linkOfRecord_;
  std::vector<BlockSlot> pairSlots_;  // per point, upper-triangular pairs of its links
  std::vector<int> pairStart_;
  std::array<std::vector<BlockSlot>, kNumTerms> edgeSlot_;  // pose-graph cross blocks
  std::array<AlignedVector<PoseBlock>, kNumTerms> edgeCross_;
  ReducedCameraSystem system_;
  AlignedVector<PoseBlock> poseHessian_;
  Eigen::VectorXd poseRhs_, poseStep_, poseDiagonal_;
  AlignedVector<Eigen::Matrix3d> pointHessian_, pointInverse_;
  AlignedVector<Eigen::Vector3d> pointRhs_, pointStep_, pointDiagonal_;
  AlignedVector<CrossBlock> cross_, crossTimesInverse_;
  AlignedVector<Pose> candidatePoses_;
  AlignedVector<Eigen::Vector3d> candidatePoints_;
  double minDiagonal_ = 1e-6, maxDiagonal_ = 1e32;
  // Threads sharing the solve, and which of them adds into each block column of the reduced
  // system (and the right-hand side of its pose): per pair of links, whose block it is.
  int threads_ = 1;
  std::vector<std::uint8_t> poseOwner_;  // per free pose
  // linearizeInParallel: every record's whitened residual and Jacobians, before they are summed.
  template <class R>
  struct LinearisedRecords {
    AlignedVector<ResidualVector<R>> residual;
    AlignedVector<PoseJacobian<R>> jPose;
    AlignedVector<PointJacobian<R>> jPoint;
  };
  static constexpr bool kOnlyPointResiduals = (PointResidual<typename Terms::Residual> && ...);
  std::tuple<LinearisedRecords<typename Terms::Residual>...> linearised_;
  std::vector<std::uint8_t> pairOwner_, linkOwner_;
  std::array<std::vector<double>, kNumTerms> recordRho_;
  std::vector<double> pointDecrease_, pointDamping_, pointStepSquared_;
};

}  // namespace orbis::optim

#include "orbis/optim/problem_impl.hpp"
