// orbis/optim/residual.hpp — what a residual block must provide to the solver.
//
// Contract: a residual type R is a small value (its measurement and whatever constants it needs)
// with compile-time sizes: kDim rows, evaluated against one pose and one 3-D point
// (PointResidual: reprojection errors) or against two poses (PoseResidual: pose-graph edges).
// evaluate() writes the raw residual and, when the pointers are non-null, its analytic Jacobians
// with respect to the manifold's local update δ at δ = 0. The solver whitens with the record's
// isotropic information (Ω = information·I, ORB-SLAM's I/σ²) and applies the term's kernel with
// the record's threshold. Jacobians must never be requested for values the residual cannot
// evaluate; a residual does not throw.
#pragma once

#include "orbis/optim/manifold.hpp"
#include "orbis/optim/robust_kernel.hpp"

#include <Eigen/Core>

#include <cmath>
#include <limits>

namespace orbis::optim {

// @{
// A residual's vector and its Jacobians for the pose and the point.
template <class R>
using ResidualVector = Eigen::Matrix<double, R::kDim, 1>;
template <class R>
using PoseJacobian = Eigen::Matrix<double, R::kDim, R::PoseManifold::kDim>;
template <class R>
using PointJacobian = Eigen::Matrix<double, R::kDim, 3>;
// @}

template <class R>
concept PointResidual = Manifold<typename R::PoseManifold> && R::kHasPoint &&
    requires(const R& r, const typename R::PoseManifold::Value& pose, const Eigen::Vector3d& point,
             ResidualVector<R>& res, PoseJacobian<R>* jPose, PointJacobian<R>* jPoint) {
      r.evaluate(pose, point, res, jPose, jPoint);
    };

template <class R>
concept PoseResidual = Manifold<typename R::PoseManifold> && !R::kHasPoint &&
    requires(const R& r, const typename R::PoseManifold::Value& poseI,
             const typename R::PoseManifold::Value& poseJ, ResidualVector<R>& res,
             PoseJacobian<R>* jI, PoseJacobian<R>* jJ) {
      r.evaluate(poseI, poseJ, res, jI, jJ);
    };

template <class R>
concept ResidualBlock = PointResidual<R> || PoseResidual<R>;

// One kind of residual in a problem: the residual type and its robust kernel, both fixed at
// compile time. A problem lists its terms, e.g. Problem<SE3Manifold, Term<Mono, HuberKernel>,
// Term<Stereo, HuberKernel>>.
template <ResidualBlock R, RobustKernel K = TrivialKernel>
struct Term {
  // @{
  // The residual and kernel types.
  using Residual = R;
  using Kernel = K;
  // @}
};

// A residual block as stored in a problem.
template <class R>
struct ResidualRecord {
  // The residual.
  R residual;
  int pose = -1;   // the observing pose, or pose i of a pose-graph edge
  int other = -1;  // the point (PointResidual) or pose j (PoseResidual)
  // 1/σ².
  double information = 1.0;
  double delta2 = std::numeric_limits<double>::infinity();  // kernel threshold δ²
  // Whether it takes part in the solve.
  bool active = true;
};

// Handle returned by Problem::add: which term, which record of it.
struct ResidualId {
  // @{
  // The term and the record's index in it.
  int term = -1;
  int index = -1;
  // @}
};

// Whitens r and the Jacobians, then applies the robust correction of Triggs et al. (as in
// Ceres' Corrector) so that the Gauss–Newton model matches ρ to second order.
template <int R, class... Jacobians>
void whitenAndCorrect(double information, const KernelValue& k, double s,
                      Eigen::Matrix<double, R, 1>& r, Jacobians*... jacobians) {
  const double sqrtInfo = std::sqrt(information);
  r *= sqrtInfo;
  const double sqrtRho1 = std::sqrt(k.rho1);
  double residualScale = sqrtRho1;
  double alphaOverS = 0.0;
  if (s > 0.0 && k.rho2 > 0.0) {
    const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * s * k.rho2 / k.rho1);
    residualScale = sqrtRho1 / (1.0 - alpha);
    alphaOverS = alpha / s;
  }
  auto correct = [&](auto* jac) {
    if (!jac) return;
    *jac *= sqrtInfo;
    if (alphaOverS != 0.0) {
      *jac = sqrtRho1 * (*jac - alphaOverS * r * (r.transpose() * *jac));
    } else {
      *jac *= sqrtRho1;
    }
  };
  (correct(jacobians), ...);
  r *= residualScale;
}

}  // namespace orbis::optim
