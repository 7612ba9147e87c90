// orbis/optim/pose_only_problem.hpp — one free pose against fixed points: the motion-only BA
// of tracking, solved without the sparse machinery of Problem.
//
// Contract: PoseOnlyProblem<Kernel, Residual...> holds one pose, a span of fixed 3-D points (the
// caller keeps them alive) and, per residual type, records of the pose observing a point. solve()
// runs levenbergMarquardt and returns exactly the bits Problem<PoseManifold, Term<Residual,
// Kernel>...> returns with the same pose free and every point fixed: each sum is formed over the
// same terms in the same order with the same expressions, and the damped system is factorised by
// the same dynamic-size LLT. setRobust(false) evaluates TrivialKernel instead of Kernel (the
// rounds "without kernel"). Pinhole reprojection residuals under Huber or no kernel are evaluated
// four at a time where the CPU has AVX2 (pinhole_pose_kernel.hpp), with the same bits. Why it
// exists: Problem rebuilds its block structure, maps over every point and copies them for each
// solve (four per frame); at a pose and ~300 fixed points that overhead is a large share of the
// solve. Not thread-safe.
#pragma once

#include "orbis/camera/pinhole.hpp"
#include "orbis/optim/levenberg_marquardt.hpp"
#include "orbis/optim/pinhole_pose_kernel.hpp"
#include "orbis/optim/reprojection.hpp"
#include "orbis/optim/residual.hpp"
#include "orbis/optim/robust_kernel.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <tuple>
#include <type_traits>
#include <utility>

namespace orbis::optim {

// One free pose observing fixed points through residuals of the listed types, under Kernel.
template <RobustKernel Kernel, PointResidual... Residuals>
class PoseOnlyProblem {
  static_assert(sizeof...(Residuals) > 0, "a problem needs at least one residual type");
  using FirstResidual = std::tuple_element_t<0, std::tuple<Residuals...>>;

 public:
  // @{
  // The pose manifold, its value type and its size.
  using PoseM = typename FirstResidual::PoseManifold;
  using Pose = typename PoseM::Value;
  static constexpr int kPoseDim = PoseM::kDim;
  // @}
  static_assert((std::is_same_v<typename Residuals::PoseManifold, PoseM> && ...),
                "every residual must be written against the same pose manifold");

  // `points` must outlive the problem; they are never written.
  PoseOnlyProblem(const Pose& pose, std::span<const Eigen::Vector3d> points)
      : pose_(pose), candidate_(pose), points_(points) {
    dense_.setZero(kPoseDim, kPoseDim);  // only the lower triangle is written and read
    gradient_.resize(kPoseDim);
    step_.resize(kPoseDim);
    diagonal_.resize(kPoseDim);
  }

  // Problem::add's signature, so the same helpers fill either: `pose` must be 0, `point` indexes
  // the fixed points; delta2 is the kernel threshold δ².
  template <PointResidual R>
  ResidualId add(const R& residual, [[maybe_unused]] int pose, int point, double information = 1.0,
                 double delta2 = std::numeric_limits<double>::infinity()) {
    constexpr int term = termOf<R>();
    static_assert(term >= 0, "residual type is not one of the problem's");
    auto& records = std::get<term>(records_);
    records.push_back(ResidualRecord<R>{residual, 0, point, information, delta2, true});
    pinholeValid_ = false;
    return {term, static_cast<int>(records.size()) - 1};
  }
  // @{
  // The pose, read and set.
  const Pose& pose() const { return pose_; }
  void setPose(const Pose& pose) { pose_ = pose; }
  // @}
  // Kernel (true, the default) or TrivialKernel (false) from the next solve on.
  void setRobust(bool robust) { robust_ = robust; }
  // Switches a residual on or off (outliers are switched off).
  void setActive(ResidualId id, bool active) {
    visitTerm(id.term, [&](auto& records) {
      if (records[id.index].active != active) pinholeValid_ = false;
      records[id.index].active = active;
    });
  }
  // information·‖r‖² at the current pose.
  double chi2(ResidualId id) const {
    double result = 0.0;
    visitTerm(id.term, [&](const auto& records) {
      const auto& rec = records[id.index];
      result = rec.information * rawResidual(rec, pose_).squaredNorm();
    });
    return result;
  }

  // Solves by Levenberg–Marquardt from the current pose, which it updates.
  SolverSummary solve(const SolverOptions& options = {}) {
    minDiagonal_ = options.minDiagonal;
    maxDiagonal_ = options.maxDiagonal;
    return levenbergMarquardt(*this, options);
  }

  // ---- LinearizedModel interface (used by levenbergMarquardt) ----
  // The pose is always free.
  bool hasFreeVariables() const { return true; }
  // Residuals and Jacobians at the current pose into the 6×6 normal equations; returns the cost.
  double linearize();
  // The largest gradient entry.
  double maxGradient() const { return gradient_.cwiseAbs().maxCoeff(); }
  // Solves the damped system for a step; false when it failed numerically.
  bool solveDamped(double mu, double& predictedDecrease, double& stepNorm);
  // Norm of the pose's parameters.
  double parameterNorm() const {
    double sq = 0.0;
    sq += PoseM::squaredNorm(pose_);
    return std::sqrt(sq);
  }
  // Cost at the current pose plus the last step.
  double candidateCost();
  // Makes the last step the current pose.
  void acceptCandidate() { std::swap(pose_, candidate_); }

 private:
  using PoseBlock = Eigen::Matrix<double, kPoseDim, kPoseDim>;

  template <class R, std::size_t... I>
  static constexpr int termOfImpl(std::index_sequence<I...>) {
    int found = -1;
    ((found < 0 && std::is_same_v<R, std::tuple_element_t<I, std::tuple<Residuals...>>> ? (found = static_cast<int>(I))
                                                                                          : 0),
     ...);
    return found;
  }
  template <class R>
  static constexpr int termOf() {
    return termOfImpl<R>(std::index_sequence_for<Residuals...>{});
  }
  template <class F>
  void visitTerm(int term, F&& f) {
    int i = 0;
    std::apply([&](auto&... records) { ((i++ == term ? f(records) : void()), ...); }, records_);
  }
  template <class F>
  void visitTerm(int term, F&& f) const {
    int i = 0;
    std::apply([&](const auto&... records) { ((i++ == term ? f(records) : void()), ...); }, records_);
  }
  // hessian_ += JᵀJ on and above the diagonal, all solveDamped reads: each entry is the sum
  // Problem forms for it (row products added in row order), half the products of the full block.
  template <int Rows>
  void addUpperGramian(const Eigen::Matrix<double, Rows, kPoseDim>& j) {
    for (int c = 0; c < kPoseDim; ++c)
      for (int r = 0; r <= c; ++r) {
        double sum = j(0, r) * j(0, c);
        for (int k = 1; k < Rows; ++k) sum = sum + j(k, r) * j(k, c);
        hessian_(r, c) += sum;
      }
  }
  // Each term's records with the term's index: f.template operator()<I>(records).
  template <class F>
  void forEachTerm(F&& f) const {
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (f.template operator()<static_cast<int>(I)>(std::get<I>(records_)), ...);
    }(std::index_sequence_for<Residuals...>{});
  }

  // ---- Pinhole reprojection residuals four at a time (pinhole_pose_kernel.hpp) ----
  // The term they are, if any, and whether this kernel is one the four-at-a-time code evaluates.
  static constexpr int pinholeTerm() { return std::is_same_v<PoseM, SE3Manifold> ? termOf<MonoReprojection>() : -1; }
  bool pinholeHuber() const { return robust_ && std::is_same_v<Kernel, HuberKernel>; }
  bool pinholeKernelFits() const {
    return !robust_ || std::is_same_v<Kernel, HuberKernel> || std::is_same_v<Kernel, TrivialKernel>;
  }
  // Whether linearize() and candidateCost() take the term's active residuals four at a time;
  // (re)builds their arrays after add() or setActive() changed them.
  bool pinholeReady() {
    if constexpr (pinholeTerm() < 0) {
      return false;
    } else {
      if (!pinholeKernelFits() || !detail::pinholePoseKernelAvailable()) return false;
      if (!pinholeValid_) {
        pinholeValid_ = true;
        pinhole_.clear();
        pinholeCamera_ = nullptr;
        pinholeUsable_ = true;
        const auto& records = std::get<static_cast<std::size_t>(pinholeTerm())>(records_);
        for (std::size_t e = 0; e < records.size(); ++e) {
          const auto& rec = records[e];
          if (!rec.active) continue;
          if (pinholeCamera_ && rec.residual.camera != pinholeCamera_) pinholeUsable_ = false;  // one camera only
          pinholeCamera_ = rec.residual.camera;
          pinhole_.push(points_[static_cast<std::size_t>(rec.other)].data(), rec.residual.measurement.data(),
                        rec.information, rec.delta2, static_cast<int>(e));
        }
      }
      return pinholeUsable_ && pinholeCamera_ != nullptr;
    }
  }
  detail::PinholePose pinholePose(const Pose& pose) const {
    const auto& q = pose.unitQuaternion();
    const auto& t = pose.translation();
    return {{q.x(), q.y(), q.z(), q.w()}, {t.x(), t.y(), t.z()},
            pinholeCamera_->fx, pinholeCamera_->fy, pinholeCamera_->cx, pinholeCamera_->cy};
  }

  KernelValue kernel(double s, double delta2) const {
    return robust_ ? Kernel::evaluate(s, delta2) : TrivialKernel::evaluate(s, delta2);
  }
  template <class R>
  ResidualVector<R> rawResidual(const ResidualRecord<R>& rec, const Pose& pose) const {
    ResidualVector<R> r;
    rec.residual.evaluate(pose, points_[static_cast<std::size_t>(rec.other)], r, nullptr, nullptr);
    return r;
  }

  Pose pose_, candidate_;
  std::span<const Eigen::Vector3d> points_;
  std::tuple<AlignedVector<ResidualRecord<Residuals>>...> records_;
  bool robust_ = true;
  detail::PinholeResiduals pinhole_;
  const PinholeCamera<double>* pinholeCamera_ = nullptr;
  bool pinholeValid_ = false, pinholeUsable_ = false;
  PoseBlock hessian_;
  // Dynamic-size like Problem's pose vectors and reduced system, so that every reduction and the
  // factorisation take the same code path (a fixed-size dot product sums in another order).
  Eigen::VectorXd gradient_, step_, diagonal_;
  Eigen::MatrixXd dense_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  double minDiagonal_ = 1e-6, maxDiagonal_ = 1e32;
};

template <RobustKernel Kernel, PointResidual... Residuals>
double PoseOnlyProblem<Kernel, Residuals...>::linearize() {
  constexpr int D = kPoseDim;
  hessian_.setZero();
  gradient_.setZero();
  double cost = 0.0;
  forEachTerm([&]<int I>(const auto& records) {
    std::size_t first = 0;  // records before it were taken four at a time
    if constexpr (I == pinholeTerm()) {
      if (pinholeReady()) {
        const std::size_t taken = detail::linearizePinholeBlocks(pinholePose(pose_), pinhole_, pinholeHuber(), cost,
                                                                 hessian_.data(), gradient_.data());
        first = taken == 0 ? 0 : static_cast<std::size_t>(pinhole_.record[taken - 1]) + 1;
      }
    }
    for (std::size_t e = first; e < records.size(); ++e) {
      const auto& rec = records[e];
      using R = std::decay_t<decltype(rec.residual)>;
      if (!rec.active) continue;
      ResidualVector<R> r;
      PoseJacobian<R> jPose;
      rec.residual.evaluate(pose_, points_[static_cast<std::size_t>(rec.other)], r, &jPose, nullptr);
      const double s = rec.information * r.squaredNorm();
      const KernelValue k = kernel(s, rec.delta2);
      cost += 0.5 * k.rho;
      whitenAndCorrect(rec.information, k, s, r, &jPose);
      addUpperGramian(jPose);
      gradient_.template segment<D>(0).noalias() -= jPose.transpose() * r;
    }
  });
  return cost;
}

template <RobustKernel Kernel, PointResidual... Residuals>
bool PoseOnlyProblem<Kernel, Residuals...>::solveDamped(double mu, double& predictedDecrease, double& stepNorm) {
  constexpr int D = kPoseDim;
  PoseBlock h = hessian_;
  for (int d = 0; d < D; ++d) {
    const double diag = std::clamp(h(d, d), minDiagonal_, maxDiagonal_);
    diagonal_[d] = diag;
    h(d, d) += mu * diag;
  }
  // Problem adds the upper triangle into a zeroed block store and factorises its transpose.
  for (int c = 0; c < D; ++c)
    for (int r = 0; r <= c; ++r) dense_(c, r) = 0.0 + h(r, c);
  llt_.compute(dense_);
  if (llt_.info() != Eigen::Success) return false;
  step_ = gradient_;
  Eigen::Map<Eigen::VectorXd>(step_.data(), D) = llt_.solve(Eigen::Map<const Eigen::VectorXd>(step_.data(), D));
  if (!std::isfinite(step_[0])) return false;
  const double decrease = step_.dot(gradient_);
  const double dampingTerm = (step_.array().square() * diagonal_.array()).sum();
  const double stepSquared = step_.squaredNorm();
  predictedDecrease = 0.5 * (decrease + mu * dampingTerm);
  stepNorm = std::sqrt(stepSquared);
  return std::isfinite(predictedDecrease);
}

template <RobustKernel Kernel, PointResidual... Residuals>
double PoseOnlyProblem<Kernel, Residuals...>::candidateCost() {
  candidate_ = PoseM::plus(pose_, step_.template segment<kPoseDim>(0));
  double cost = 0.0;
  forEachTerm([&]<int I>(const auto& records) {
    std::size_t first = 0;
    if constexpr (I == pinholeTerm()) {
      if (pinholeReady()) {
        const std::size_t taken = detail::costPinholeBlocks(pinholePose(candidate_), pinhole_, pinholeHuber(), cost);
        first = taken == 0 ? 0 : static_cast<std::size_t>(pinhole_.record[taken - 1]) + 1;
      }
    }
    for (std::size_t e = first; e < records.size(); ++e) {
      const auto& rec = records[e];
      if (!rec.active) continue;
      const double s = rec.information * rawResidual(rec, candidate_).squaredNorm();
      cost += 0.5 * kernel(s, rec.delta2).rho;
    }
  });
  return cost;
}

}  // namespace orbis::optim
