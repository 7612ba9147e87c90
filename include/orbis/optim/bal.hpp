// orbis/optim/bal.hpp — BAL's 9-parameter camera as a user-defined residual, solved by the same
// engine as the SLAM problems, and the export of a SLAM reprojection problem to BAL for replay.
//
// Contract: BalReprojection implements BAL's model (see orbis/optim/bal_problem.hpp) with analytic
// Jacobians; the camera block is Euclidean (δ added to angle-axis, translation, f, k1, k2, as
// Ceres' BAL example does). solveBal() builds the problem with Huber loss δ on the pixel
// residuals, solves it in place and reports costs in Ceres' convention. exportBal() turns a
// monocular/stereo SE(3) problem into BAL form: same poses and points, the left-image pixel of
// each active reprojection residual re-expressed in BAL's centred, negated convention with
// f = fx (v is rescaled by fx/fy), k1 = k2 = 0; information weights and kernels are not
// representable in BAL and are dropped.
#pragma once

#include "orbis/geometry/so3.hpp"
#include "orbis/optim/bal_problem.hpp"
#include "orbis/optim/manifold.hpp"
#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"

#include <Eigen/Core>

namespace orbis::optim {

// BAL's reprojection residual: a 9-parameter camera (rotation vector, translation, f, k1, k2)
// seeing a point; a user-defined residual on a Euclidean pose block.
struct BalReprojection {
  // @{
  // A 9-dimensional Euclidean camera block, 2 residual rows, with a point.
  using PoseManifold = EuclideanManifold<9>;
  static constexpr int kDim = 2;
  static constexpr bool kHasPoint = true;
  // @}

  // The observed pixel (BAL's centred coordinates).
  Eigen::Vector2d measurement;

  // Residual and Jacobians (either may be null).
  void evaluate(const Eigen::Matrix<double, 9, 1>& camera, const Eigen::Vector3d& point,
                Eigen::Vector2d& r, Eigen::Matrix<double, 2, 9>* jCamera,
                Eigen::Matrix<double, 2, 3>* jPoint) const {
    const Eigen::Vector3d omega = camera.head<3>();
    const Eigen::Matrix3d rotation = SO3d::exp(omega).matrix();
    const Eigen::Vector3d pc = rotation * point + camera.segment<3>(3);
    const double invZ = 1.0 / pc.z();
    const Eigen::Vector2d p = -pc.head<2>() * invZ;
    const double f = camera[6], k1 = camera[7], k2 = camera[8];
    const double n = p.squaredNorm();
    const double radial = 1.0 + n * (k1 + k2 * n);
    r = f * radial * p - measurement;
    if (!jCamera && !jPoint) return;
    Eigen::Matrix<double, 2, 3> dpdP;
    dpdP << -invZ, 0.0, pc.x() * invZ * invZ,  //
        0.0, -invZ, pc.y() * invZ * invZ;
    const Eigen::Matrix2d dPixeldp =
        f * (radial * Eigen::Matrix2d::Identity() + 2.0 * (k1 + 2.0 * k2 * n) * p * p.transpose());
    const Eigen::Matrix<double, 2, 3> dPixeldP = dPixeldp * dpdP;
    if (jCamera) {
      // R(ω + dω) ≈ R·exp(J_r(ω)dω), so ∂(R·X)/∂ω = −R·hat(X)·J_r(ω).
      jCamera->leftCols<3>().noalias() =
          -dPixeldP * rotation * SO3d::hat(point) * SO3d::rightJacobian(omega);
      jCamera->middleCols<3>(3) = dPixeldP;
      jCamera->col(6) = radial * p;
      jCamera->col(7) = f * n * p;
      jCamera->col(8) = f * n * n * p;
    }
    if (jPoint) jPoint->noalias() = dPixeldP * rotation;
  }
};

// A BAL problem as the solver holds it, Huber kernel on every observation.
using BalBundleProblem = Problem<EuclideanManifold<9>, Term<BalReprojection, HuberKernel>>;

// Builds the engine's problem from a BAL file's contents (nothing fixed, Huber δ on pixels).
BalBundleProblem makeBalProblem(const BalProblem& bal, double huberDelta = 1.0);
// Solves in place: bal's cameras and points are overwritten with the solution.
SolverSummary solveBal(BalProblem& bal, const SolverOptions& options = {}, double huberDelta = 1.0);

// A SLAM reprojection problem (mono and/or stereo terms over SE3 poses) in BAL form.
template <class... Terms>
BalProblem exportBal(const Problem<SE3Manifold, Terms...>& problem);

}  // namespace orbis::optim

#include "orbis/optim/bal_export_impl.hpp"
