#include "orbis/loop/relative_pose.hpp"

#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Geometry>

#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"
#include "two_way_fit.hpp"

namespace orbis::loop {

namespace {

using RelativePoseProblem =
    optim::Problem<optim::SE3Manifold, optim::Term<optim::MonoReprojection, optim::HuberKernel>,
                   optim::Term<optim::InversePoseReprojection<PinholeCamera<double>>, optim::HuberKernel>>;

}  // namespace

PairChi2 pairChi2(const PinholeCamera<double>& camera, const SE3d& T12, const PointPair& pair) {
  return detail::twoWayChi2(camera, T12, pair);
}

SE3d alignPoints(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) {
  const Eigen::Matrix4d T = Eigen::umeyama(source, target, false);
  return SE3d::fromMatrix(T);
}

RelativePoseEstimate estimateRelativePoseRansac(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera,
                                                const RelativePoseRansacOptions& options, std::mt19937& rng) {
  // A degenerate (near-collinear) triple gives no rotation.
  const auto fitTriple = [](const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) -> std::optional<SE3d> {
    const Eigen::Vector3d e1 = source.col(1) - source.col(0), e2 = source.col(2) - source.col(0);
    if (e1.cross(e2).norm() < 1e-6 * e1.norm() * e2.norm() + 1e-12) return std::nullopt;
    return alignPoints(source, target);
  };
  const auto fitAll = [](const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) -> std::optional<SE3d> {
    return alignPoints(source, target);
  };
  const auto score = [&](const SE3d& T, std::vector<char>& inliers) {
    return detail::classify(pairs, camera, T, options.inlierChi2, false, inliers);
  };
  const auto never = [](int) { return std::numeric_limits<double>::infinity(); };
  const detail::RansacResult<SE3d> r =
      detail::ransacOverTriples<SE3d>(pairs, options.iterations, options.minInliers, rng, fitTriple, fitAll, score, never);
  RelativePoseEstimate best;
  if (!r.found) return best;
  best.found = true;
  best.T12 = r.model;
  best.inliers = r.inliers;
  best.inlierCount = r.inlierCount;
  return best;
}

int refineRelativePose(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, SE3d& T12,
                       std::vector<char>& inliers, double outlierChi2) {
  return detail::refineTwoWay<RelativePoseProblem, optim::MonoReprojection,
                              optim::InversePoseReprojection<PinholeCamera<double>>>(pairs, camera, T12, inliers,
                                                                                      outlierChi2);
}

}  // namespace orbis::loop
