// orbis/optim/problem_impl.hpp — out-of-class members of Problem (structure, linearisation,
// Schur complement). Included by problem.hpp only.
//
// Contract: as problem.hpp. The Schur loop visits each free point once per damped solve: it
// inverts the point's damped 3×3 block, folds the point into the right-hand side, and subtracts
// W_a V⁻¹ W_bᵀ from the reduced camera block of every pair (a, b) of poses observing it, at
// slots looked up once per structure.
// Threads (SolverOptions::threads) share that loop without changing the result: the per-point
// work (inverse, W V⁻¹) goes to any thread, but every block column of the reduced system, and
// the right-hand side of its pose, is added to by one owner thread only, which visits the points
// in the serial order; so every sum is formed in the same order as on one thread. The
// back-substitution and the cost keep per-point and per-record terms and sum them in order.
#pragma once

#include "orbis/optim/problem.hpp"

namespace orbis::optim {

template <Manifold PoseM, class... Terms>
void Problem<PoseM, Terms...>::prepare(const SolverOptions& options) {
  constexpr int D = kPoseDim;
  auto index = [](const std::vector<char>& fixed, std::vector<int>& map, std::vector<int>& ids) {
    map.assign(fixed.size(), -1);
    ids.clear();
    for (std::size_t i = 0; i < fixed.size(); ++i) {
      if (!fixed[i]) {
        map[i] = static_cast<int>(ids.size());
        ids.push_back(static_cast<int>(i));
      }
    }
  };
  index(poseFixed_, freePose_, freePoseIds_);
  index(pointFixed_, freePoint_, freePointIds_);
  const int numFreePoses = static_cast<int>(freePoseIds_.size());
  const int numFreePoints = static_cast<int>(freePointIds_.size());

  // Links grouped by point, sorted by pose inside each point so that pairs are upper-triangular.
  linkStart_.assign(static_cast<std::size_t>(numFreePoints) + 1, 0);
  forEachTerm([&]<std::size_t I>() {
    if constexpr (PointResidual<ResidualAt<I>>) {
      for (const auto& rec : std::get<I>(records_)) {
        if (rec.active && freePose_[rec.pose] >= 0 && freePoint_[rec.other] >= 0) {
          ++linkStart_[freePoint_[rec.other] + 1];
        }
      }
    }
  });
  for (int l = 0; l < numFreePoints; ++l) linkStart_[l + 1] += linkStart_[l];
  links_.resize(linkStart_[numFreePoints]);
  {
    std::vector<int> fill(linkStart_.begin(), linkStart_.end() - 1);
    forEachTerm([&]<std::size_t I>() {
      const auto& records = std::get<I>(records_);
      linkOfRecord_[I].assign(records.size(), -1);
      if constexpr (PointResidual<ResidualAt<I>>) {
        for (std::size_t e = 0; e < records.size(); ++e) {
          const auto& rec = records[e];
          if (rec.active && freePose_[rec.pose] >= 0 && freePoint_[rec.other] >= 0) {
            links_[fill[freePoint_[rec.other]]++] = {freePose_[rec.pose], static_cast<int>(I),
                                                     static_cast<int>(e)};
          }
        }
      }
    });
  }
  for (int l = 0; l < numFreePoints; ++l) {
    auto first = links_.begin() + linkStart_[l], last = links_.begin() + linkStart_[l + 1];
    std::stable_sort(first, last, [](const Link& a, const Link& b) { return a.pose < b.pose; });
  }
  for (std::size_t k = 0; k < links_.size(); ++k) {
    linkOfRecord_[links_[k].term][links_[k].index] = static_cast<int>(k);
  }

  // Block pattern of the reduced camera system.
  BlockPatternBuilder pattern;
  pattern.reset(numFreePoses);
  for (int l = 0; l < numFreePoints; ++l) {
    for (int a = linkStart_[l]; a < linkStart_[l + 1]; ++a) {
      for (int b = a + 1; b < linkStart_[l + 1]; ++b) pattern.add(links_[a].pose, links_[b].pose);
    }
  }
  forEachTerm([&]<std::size_t I>() {
    if constexpr (PoseResidual<ResidualAt<I>>) {
      for (const auto& rec : std::get<I>(records_)) {
        const int i = freePose_[rec.pose], j = freePose_[rec.other];
        if (rec.active && i >= 0 && j >= 0) pattern.add(i, j);
      }
    }
  });
  system_.setPattern(pattern, D, options.linearSolver, options.denseThreshold);

  pairStart_.assign(static_cast<std::size_t>(numFreePoints) + 1, 0);
  pairSlots_.clear();
  for (int l = 0; l < numFreePoints; ++l) {
    pairStart_[l] = static_cast<int>(pairSlots_.size());
    for (int a = linkStart_[l]; a < linkStart_[l + 1]; ++a) {
      for (int b = a; b < linkStart_[l + 1]; ++b) {
        const int i = links_[a].pose, j = links_[b].pose;
        pairSlots_.push_back(i == j ? system_.diagonalSlot(i) : system_.slot(i, j));
      }
    }
  }
  pairStart_[numFreePoints] = static_cast<int>(pairSlots_.size());
  forEachTerm([&]<std::size_t I>() {
    const auto& records = std::get<I>(records_);
    edgeSlot_[I].clear();
    if constexpr (PoseResidual<ResidualAt<I>>) {
      edgeSlot_[I].resize(records.size());
      edgeCross_[I].resize(records.size());
      for (std::size_t e = 0; e < records.size(); ++e) {
        const int i = freePose_[records[e].pose], j = freePose_[records[e].other];
        if (records[e].active && i >= 0 && j >= 0 && i != j) {
          edgeSlot_[I][e] = system_.slot(std::min(i, j), std::max(i, j));
        }
      }
    }
  });

  poseHessian_.resize(numFreePoses);
  poseRhs_.resize(numFreePoses * D);
  poseStep_.resize(numFreePoses * D);
  poseDiagonal_.resize(numFreePoses * D);
  pointHessian_.resize(numFreePoints);
  pointInverse_.resize(numFreePoints);
  pointRhs_.resize(numFreePoints);
  pointStep_.resize(numFreePoints);
  pointDiagonal_.resize(numFreePoints);
  cross_.resize(links_.size());
  crossTimesInverse_.resize(links_.size());
  pointDecrease_.resize(numFreePoints);
  pointDamping_.resize(numFreePoints);
  pointStepSquared_.resize(numFreePoints);
  threads_ = pairSlots_.size() >= kMinPairsForThreads ? std::clamp(options.threads, 1, 64) : 1;
  assignColumnOwners(threads_);
  candidatePoses_ = poses_;
  candidatePoints_ = points_;
  minDiagonal_ = options.minDiagonal;
  maxDiagonal_ = options.maxDiagonal;
}

template <Manifold PoseM, class... Terms>
double Problem<PoseM, Terms...>::linearizeSerially() {
  constexpr int D = kPoseDim;
  for (auto& h : poseHessian_) h.setZero();
  poseRhs_.setZero();
  for (auto& h : pointHessian_) h.setZero();
  for (auto& b : pointRhs_) b.setZero();
  double cost = 0.0;
  forEachTerm([&]<std::size_t I>() {
    using R = ResidualAt<I>;
    using Kernel = typename TermAt<I>::Kernel;
    const auto& records = std::get<I>(records_);
    for (std::size_t e = 0; e < records.size(); ++e) {
      const auto& rec = records[e];
      if (!rec.active) continue;
      ResidualVector<R> r;
      PoseJacobian<R> jPose;
      if constexpr (PointResidual<R>) {
        const int fp = freePose_[rec.pose], fl = freePoint_[rec.other];
        PointJacobian<R> jPoint;
        rec.residual.evaluate(poses_[rec.pose], points_[rec.other], r, fp >= 0 ? &jPose : nullptr,
                              fl >= 0 ? &jPoint : nullptr);
        const double s = rec.information * r.squaredNorm();
        const KernelValue k = Kernel::evaluate(s, rec.delta2);
        cost += 0.5 * k.rho;
        if (fp < 0 && fl < 0) continue;
        whitenAndCorrect(rec.information, k, s, r, fp >= 0 ? &jPose : nullptr,
                         fl >= 0 ? &jPoint : nullptr);
        if (fp >= 0) {
          poseHessian_[fp].noalias() += jPose.transpose().lazyProduct(jPose);
          poseRhs_.template segment<D>(fp * D).noalias() -= jPose.transpose() * r;
        }
        if (fl >= 0) {
          pointHessian_[fl].noalias() += jPoint.transpose().lazyProduct(jPoint);
          pointRhs_[fl].noalias() -= jPoint.transpose() * r;
          if (fp >= 0) cross_[linkOfRecord_[I][e]].noalias() = jPose.transpose().lazyProduct(jPoint);
        }
      } else {
        int fi = freePose_[rec.pose], fj = freePose_[rec.other];
        PoseJacobian<R> jOther;
        rec.residual.evaluate(poses_[rec.pose], poses_[rec.other], r, fi >= 0 ? &jPose : nullptr,
                              fj >= 0 ? &jOther : nullptr);
        const double s = rec.information * r.squaredNorm();
        const KernelValue k = Kernel::evaluate(s, rec.delta2);
        cost += 0.5 * k.rho;
        if (fi < 0 && fj < 0) continue;
        if (fi == fj) {  // an edge from a pose to itself acts through the sum of its Jacobians
          jPose += jOther;
          fj = -1;
        }
        whitenAndCorrect(rec.information, k, s, r, fi >= 0 ? &jPose : nullptr,
                         fj >= 0 ? &jOther : nullptr);
        if (fi >= 0) {
          poseHessian_[fi].noalias() += jPose.transpose().lazyProduct(jPose);
          poseRhs_.template segment<D>(fi * D).noalias() -= jPose.transpose() * r;
        }
        if (fj >= 0) {
          poseHessian_[fj].noalias() += jOther.transpose().lazyProduct(jOther);
          poseRhs_.template segment<D>(fj * D).noalias() -= jOther.transpose() * r;
        }
        if (fi >= 0 && fj >= 0) {
          if (fi < fj) {
            edgeCross_[I][e].noalias() = jPose.transpose() * jOther;
          } else {
            edgeCross_[I][e].noalias() = jOther.transpose() * jPose;
          }
        }
      }
    }
  });
  return cost;
}

// linearizeSerially's result from three passes: every record's residual and Jacobians on any
// thread; their sums into the pose and point blocks by the owner of each block (poses as in
// assignColumnOwners, points in contiguous ranges), records in serial order; the cost in record
// order. Each sum sees the same terms in the same order as in linearizeSerially.
template <Manifold PoseM, class... Terms>
double Problem<PoseM, Terms...>::linearizeInParallel() {
  constexpr int D = kPoseDim;
  forEachTerm([&]<std::size_t I>() {
    using R = ResidualAt<I>;
    using Kernel = typename TermAt<I>::Kernel;
    const auto& records = std::get<I>(records_);
    auto& lin = std::get<I>(linearised_);
    lin.residual.resize(records.size());
    lin.jPose.resize(records.size());
    lin.jPoint.resize(records.size());
    recordRho_[I].resize(records.size());
    forEachRecordInParallel(records.size(), [&](std::size_t e) {
      const auto& rec = records[e];
      if (!rec.active) return;
      const int fp = freePose_[rec.pose], fl = freePoint_[rec.other];
      ResidualVector<R>& r = lin.residual[e];
      PoseJacobian<R>* jPose = fp >= 0 ? &lin.jPose[e] : nullptr;
      PointJacobian<R>* jPoint = fl >= 0 ? &lin.jPoint[e] : nullptr;
      rec.residual.evaluate(poses_[rec.pose], points_[rec.other], r, jPose, jPoint);
      const double s = rec.information * r.squaredNorm();
      const KernelValue k = Kernel::evaluate(s, rec.delta2);
      recordRho_[I][e] = k.rho;
      if (fp < 0 && fl < 0) return;
      whitenAndCorrect(rec.information, k, s, r, jPose, jPoint);
    });
  });
  for (auto& h : poseHessian_) h.setZero();
  poseRhs_.setZero();
  for (auto& h : pointHessian_) h.setZero();
  for (auto& b : pointRhs_) b.setZero();
  const int numFreePoints = static_cast<int>(freePointIds_.size());
  parallelFor(threads_, threads_, [&](int owner) {
    const auto pointOwner = [&](int l) { return static_cast<int>(static_cast<long>(l) * threads_ / numFreePoints); };
    forEachTerm([&]<std::size_t I>() {
      const auto& records = std::get<I>(records_);
      const auto& lin = std::get<I>(linearised_);
      for (std::size_t e = 0; e < records.size(); ++e) {
        const auto& rec = records[e];
        if (!rec.active) continue;
        const int fp = freePose_[rec.pose], fl = freePoint_[rec.other];
        if (fp >= 0 && poseOwner_[fp] == owner) {
          const auto& jPose = lin.jPose[e];
          poseHessian_[fp].noalias() += jPose.transpose().lazyProduct(jPose);
          poseRhs_.template segment<D>(fp * D).noalias() -= jPose.transpose() * lin.residual[e];
        }
        if (fl >= 0 && pointOwner(fl) == owner) {
          const auto& jPoint = lin.jPoint[e];
          pointHessian_[fl].noalias() += jPoint.transpose().lazyProduct(jPoint);
          pointRhs_[fl].noalias() -= jPoint.transpose() * lin.residual[e];
          if (fp >= 0) cross_[linkOfRecord_[I][e]].noalias() = lin.jPose[e].transpose().lazyProduct(jPoint);
        }
      }
    });
  });
  double cost = 0.0;
  forEachTerm([&]<std::size_t I>() {
    const auto& records = std::get<I>(records_);
    for (std::size_t e = 0; e < records.size(); ++e)
      if (records[e].active) cost += 0.5 * recordRho_[I][e];
  });
  return cost;
}

template <Manifold PoseM, class... Terms>
void Problem<PoseM, Terms...>::assignColumnOwners(int owners) {
  // Contiguous ranges of block columns with about equal numbers of block products each.
  const int numFreePoses = static_cast<int>(freePoseIds_.size());
  std::vector<double> work(static_cast<std::size_t>(numFreePoses), 0.0);
  for (const BlockSlot& slot : pairSlots_) work[slot.column] += 1.0;
  double total = 0.0;
  for (double w : work) total += w;
  std::vector<std::uint8_t>& owner = poseOwner_;
  owner.assign(static_cast<std::size_t>(numFreePoses), 0);
  double before = 0.0;
  for (int j = 0; j < numFreePoses; ++j) {
    owner[j] = static_cast<std::uint8_t>(std::min(owners - 1, static_cast<int>(before * owners / std::max(total, 1.0))));
    before += work[j];
  }
  pairOwner_.resize(pairSlots_.size());
  for (std::size_t k = 0; k < pairSlots_.size(); ++k) pairOwner_[k] = owner[pairSlots_[k].column];
  linkOwner_.resize(links_.size());
  for (std::size_t a = 0; a < links_.size(); ++a) linkOwner_[a] = owner[links_[a].pose];
}

template <Manifold PoseM, class... Terms>
void Problem<PoseM, Terms...>::schurComplement(double mu, Eigen::VectorXd& rhs) {
  constexpr int D = kPoseDim;
  auto clampDiagonal = [this](double v) { return std::clamp(v, minDiagonal_, maxDiagonal_); };
  const int numFreePoints = static_cast<int>(freePointIds_.size());
  // Per point, on any thread: the damped inverse V⁻¹ and W V⁻¹ for each of its links.
  parallelFor(threads_, (numFreePoints + kPointsPerTask - 1) / kPointsPerTask, [&](int task) {
    for (int l = task * kPointsPerTask, end = std::min(numFreePoints, l + kPointsPerTask); l < end; ++l) {
      Eigen::Matrix3d v = pointHessian_[l];
      for (int d = 0; d < 3; ++d) {
        const double diag = clampDiagonal(v(d, d));
        pointDiagonal_[l][d] = diag;
        v(d, d) += mu * diag;
      }
      const Eigen::Matrix3d inverse = v.inverse();
      pointInverse_[l] = inverse;
      for (int a = linkStart_[l]; a < linkStart_[l + 1]; ++a) crossTimesInverse_[a].noalias() = cross_[a].lazyProduct(inverse);
    }
  });
  // Per owner: its columns' blocks and right-hand sides, the points in serial order.
  parallelFor(threads_, threads_, [&](int owner) {
    for (int l = 0; l < numFreePoints; ++l) {
      const int first = linkStart_[l], last = linkStart_[l + 1];
      for (int a = first; a < last; ++a) {
        if (linkOwner_[a] == owner)
          rhs.template segment<D>(links_[a].pose * D).noalias() -= crossTimesInverse_[a] * pointRhs_[l];
      }
      int k = pairStart_[l];
      for (int a = first; a < last; ++a) {
        const CrossBlock& y = crossTimesInverse_[a];
        for (int b = a; b < last; ++b, ++k) {
          if (pairOwner_[k] != owner) continue;
          // lazyProduct: Eigen would otherwise send these small fixed-size products to GEMM.
          const PoseBlock block = -y.lazyProduct(cross_[b].transpose());
          if (a == b) {
            system_.template addDiagonal<D>(links_[a].pose, block);
          } else {
            system_.template addSymmetrised<D>(pairSlots_[k], links_[a].pose == links_[b].pose, block);
          }
        }
      }
    }
  });
}

template <Manifold PoseM, class... Terms>
bool Problem<PoseM, Terms...>::solveDamped(double mu, double& predictedDecrease, double& stepNorm) {
  constexpr int D = kPoseDim;
  system_.setZero();
  auto clampDiagonal = [this](double v) { return std::clamp(v, minDiagonal_, maxDiagonal_); };

  const int numFreePoses = static_cast<int>(freePoseIds_.size());
  for (int i = 0; i < numFreePoses; ++i) {
    PoseBlock h = poseHessian_[i];
    for (int d = 0; d < D; ++d) {
      const double diag = clampDiagonal(h(d, d));
      poseDiagonal_[i * D + d] = diag;
      h(d, d) += mu * diag;
    }
    system_.template addDiagonal<D>(i, h);
  }
  forEachTerm([&]<std::size_t I>() {
    if constexpr (PoseResidual<ResidualAt<I>>) {
      const auto& records = std::get<I>(records_);
      for (std::size_t e = 0; e < records.size(); ++e) {
        const auto& rec = records[e];
        const int fi = freePose_[rec.pose], fj = freePose_[rec.other];
        if (rec.active && fi >= 0 && fj >= 0 && fi != fj) {
          system_.template addOffDiagonal<D>(edgeSlot_[I][e], edgeCross_[I][e]);
        }
      }
    }
  });

  Eigen::VectorXd& rhs = poseStep_;  // reduced right-hand side, solved in place
  rhs = poseRhs_;
  schurComplement(mu, rhs);

  if (numFreePoses > 0) {
    const std::span<double> reduced(poseStep_.data(), static_cast<std::size_t>(poseStep_.size()));
    if (!system_.solve(reduced, reduced)) return false;
  }

  double decrease = poseStep_.dot(poseRhs_);
  double dampingTerm = (poseStep_.array().square() * poseDiagonal_.array()).sum();
  double stepSquared = poseStep_.squaredNorm();
  const int numFreePoints = static_cast<int>(freePointIds_.size());
  parallelFor(threads_, (numFreePoints + kPointsPerTask - 1) / kPointsPerTask, [&](int task) {
    for (int l = task * kPointsPerTask, end = std::min(numFreePoints, l + kPointsPerTask); l < end; ++l) {
      Eigen::Vector3d t = pointRhs_[l];
      for (int a = linkStart_[l]; a < linkStart_[l + 1]; ++a) {
        t.noalias() -= cross_[a].transpose() * poseStep_.template segment<D>(links_[a].pose * D);
      }
      const Eigen::Vector3d step = pointInverse_[l] * t;
      pointStep_[l] = step;
      pointDecrease_[l] = step.dot(pointRhs_[l]);
      pointDamping_[l] = step.cwiseAbs2().dot(pointDiagonal_[l]);
      pointStepSquared_[l] = step.squaredNorm();
    }
  });
  for (int l = 0; l < numFreePoints; ++l) {
    decrease += pointDecrease_[l];
    dampingTerm += pointDamping_[l];
    stepSquared += pointStepSquared_[l];
  }
  predictedDecrease = 0.5 * (decrease + mu * dampingTerm);
  stepNorm = std::sqrt(stepSquared);
  return std::isfinite(predictedDecrease);
}

}  // namespace orbis::optim
