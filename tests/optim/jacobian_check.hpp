// tests/optim/jacobian_check.hpp — the one harness that checks any residual's analytic
// Jacobians against central differences taken through the residual's own manifold update.
#pragma once

#include "orbis/optim/residual.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstdio>

namespace orbis::optim::test {

struct JacobianDiscrepancy {
  double maxAbsError = 0.0;   // largest |analytic − numeric| entry
  double maxAbsEntry = 0.0;   // largest |analytic| entry, for scale
  double relative() const { return maxAbsError / std::max(1.0, maxAbsEntry); }
};

template <class Analytic, class Numeric>
void accumulate(JacobianDiscrepancy& d, const Analytic& a, const Numeric& n) {
  d.maxAbsError = std::max(d.maxAbsError, (a - n).cwiseAbs().maxCoeff());
  d.maxAbsEntry = std::max(d.maxAbsEntry, a.cwiseAbs().maxCoeff());
}

template <PointResidual R>
JacobianDiscrepancy checkJacobians(const R& residual, const typename R::PoseManifold::Value& pose,
                                   const Eigen::Vector3d& point, double h = 1e-6) {
  using M = typename R::PoseManifold;
  ResidualVector<R> r, rPlus, rMinus;
  PoseJacobian<R> jPose, nPose;
  PointJacobian<R> jPoint, nPoint;
  residual.evaluate(pose, point, r, &jPose, &jPoint);
  for (int k = 0; k < M::kDim; ++k) {
    Eigen::Matrix<double, M::kDim, 1> d = Eigen::Matrix<double, M::kDim, 1>::Zero();
    d[k] = h;
    residual.evaluate(M::plus(pose, d), point, rPlus, nullptr, nullptr);
    residual.evaluate(M::plus(pose, -d), point, rMinus, nullptr, nullptr);
    nPose.col(k) = (rPlus - rMinus) / (2 * h);
  }
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[k] = h;
    residual.evaluate(pose, point + d, rPlus, nullptr, nullptr);
    residual.evaluate(pose, point - d, rMinus, nullptr, nullptr);
    nPoint.col(k) = (rPlus - rMinus) / (2 * h);
  }
  JacobianDiscrepancy out;
  accumulate(out, jPose, nPose);
  accumulate(out, jPoint, nPoint);
  return out;
}

template <PoseResidual R>
JacobianDiscrepancy checkJacobians(const R& residual, const typename R::PoseManifold::Value& poseI,
                                   const typename R::PoseManifold::Value& poseJ, double h = 1e-6) {
  using M = typename R::PoseManifold;
  ResidualVector<R> r, rPlus, rMinus;
  PoseJacobian<R> jI, jJ, nI, nJ;
  residual.evaluate(poseI, poseJ, r, &jI, &jJ);
  for (int k = 0; k < M::kDim; ++k) {
    Eigen::Matrix<double, M::kDim, 1> d = Eigen::Matrix<double, M::kDim, 1>::Zero();
    d[k] = h;
    residual.evaluate(M::plus(poseI, d), poseJ, rPlus, nullptr, nullptr);
    residual.evaluate(M::plus(poseI, -d), poseJ, rMinus, nullptr, nullptr);
    nI.col(k) = (rPlus - rMinus) / (2 * h);
    residual.evaluate(poseI, M::plus(poseJ, d), rPlus, nullptr, nullptr);
    residual.evaluate(poseI, M::plus(poseJ, -d), rMinus, nullptr, nullptr);
    nJ.col(k) = (rPlus - rMinus) / (2 * h);
  }
  JacobianDiscrepancy out;
  accumulate(out, jI, nI);
  accumulate(out, jJ, nJ);
  return out;
}

}  // namespace orbis::optim::test
