// orbis/optim/bal_export_impl.hpp — exportBal, included by bal.hpp only.
//
// Contract: as bal.hpp. BAL's camera looks down −z: a camera-from-world pose T maps to BAL
// parameters (log R, t) unchanged, and an observation (u, v) becomes (−(u − cx), −(v − cy)·fx/fy).
#pragma once

#include "orbis/optim/bal.hpp"

namespace orbis::optim {

template <class... Terms>
BalProblem exportBal(const Problem<SE3Manifold, Terms...>& problem) {
  using P = Problem<SE3Manifold, Terms...>;
  BalProblem bal;
  bal.cameras.resize(problem.numPoses());
  std::vector<double> focal(problem.numPoses(), 0.0);
  for (int i = 0; i < problem.numPoses(); ++i) bal.cameras[i].setZero();
  bal.points.resize(problem.numPoints());
  for (int l = 0; l < problem.numPoints(); ++l) bal.points[l] = problem.point(l);
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          using R = typename P::template ResidualAt<I>;
          if constexpr (PointResidual<R> && std::is_same_v<typename R::PoseManifold, SE3Manifold>) {
            for (const auto& rec : problem.template records<I>()) {
              if (!rec.active) continue;
              const PinholeCamera<double>* pinhole = nullptr;
              if constexpr (requires { rec.residual.camera->pinhole; }) {
                pinhole = &rec.residual.camera->pinhole;
              } else {
                pinhole = rec.residual.camera;
              }
              focal[rec.pose] = pinhole->fx;
              bal.observations.push_back({rec.pose, rec.other, -(rec.residual.measurement[0] - pinhole->cx),
                                          -(rec.residual.measurement[1] - pinhole->cy) * pinhole->fx / pinhole->fy});
            }
          }
        }(),
        ...);
  }(std::index_sequence_for<Terms...>{});
  for (int i = 0; i < problem.numPoses(); ++i) {
    const SE3d& pose = problem.pose(i);
    bal.cameras[i].head<3>() = pose.so3().log();
    bal.cameras[i].segment<3>(3) = pose.translation();
    bal.cameras[i][6] = focal[i];
  }
  return bal;
}

}  // namespace orbis::optim
