#include "orbis/loop/sim3_solver.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "orbis/optim/problem.hpp"
#include "orbis/optim/sim3_reprojection.hpp"
#include "two_way_fit.hpp"

namespace orbis::loop {

namespace {

using Sim3Problem = optim::Problem<optim::Sim3Manifold, optim::Term<optim::MonoSim3Reprojection, optim::HuberKernel>,
                                   optim::Term<optim::MonoInverseSim3Reprojection, optim::HuberKernel>>;
using Lens = KannalaBrandtCamera<double>;
using LensSim3Problem =
    optim::Problem<optim::Sim3Manifold, optim::Term<optim::Sim3Reprojection<Lens>, optim::HuberKernel>,
                   optim::Term<optim::InverseSim3Reprojection<Lens>, optim::HuberKernel>>;

// Centred points spread along at least two directions: the second largest eigenvalue of their
// scatter is not negligible against the largest (collinear or coincident sets leave a rotation
// about their line free).
bool spansAPlane(const Eigen::Matrix3Xd& centred) {
  const Eigen::Matrix3d scatter = centred * centred.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(scatter, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d lambda = eigen.eigenvalues();  // ascending
  return lambda[2] > 0 && lambda[1] > 1e-10 * lambda[2];
}

// Hypotheses still needed for `confidence` that one drew three inliers, at inlier ratio w.
double iterationsNeeded(double w, double confidence) {
  const double allInliers = w * w * w;
  if (allInliers >= 1.0) return 0.0;
  if (allInliers <= 0.0) return std::numeric_limits<double>::infinity();
  return std::log(1.0 - confidence) / std::log(1.0 - allInliers);
}

}  // namespace

std::optional<Sim3d> alignSim3(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target, bool fixScale) {
  if (source.cols() < 3 || source.cols() != target.cols()) return std::nullopt;
  const Eigen::Vector3d sourceMean = source.rowwise().mean(), targetMean = target.rowwise().mean();
  const Eigen::Matrix3Xd a = source.colwise() - sourceMean, b = target.colwise() - targetMean;
  if (!spansAPlane(a) || !spansAPlane(b)) return std::nullopt;
  // Horn (1987): the rotation maximising Σ bᵢ·(R aᵢ) is the unit quaternion along the top
  // eigenvector of N, built from M = Σ aᵢ bᵢᵀ.
  const Eigen::Matrix3d M = a * b.transpose();
  const double sxx = M(0, 0), sxy = M(0, 1), sxz = M(0, 2), syx = M(1, 0), syy = M(1, 1), syz = M(1, 2),
               szx = M(2, 0), szy = M(2, 1), szz = M(2, 2);
  Eigen::Matrix4d N;
  N << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,  //
      syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,   //
      szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,  //
      sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(N);
  const Eigen::Vector4d lambda = eigen.eigenvalues();
  // A repeated top eigenvalue leaves the rotation undetermined.
  if (lambda[3] - lambda[2] <= 1e-12 * std::max(1.0, std::abs(lambda[3]))) return std::nullopt;
  const Eigen::Vector4d q = eigen.eigenvectors().col(3);
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  double s = 1.0;
  if (!fixScale) {
    // The least-squares scale of target on R·source (ORB-SLAM's, not Horn's symmetric one: the
    // reprojection test that follows measures errors on the target side).
    s = (b.array() * (R * a).array()).sum() / a.squaredNorm();
    if (!(s > 0)) return std::nullopt;
  }
  return Sim3d(s, R, targetMean - s * (R * sourceMean));
}

PairChi2 pairChi2(const PinholeCamera<double>& camera, const Sim3d& S12, const PointPair& pair) {
  return detail::twoWayChi2(camera, S12, pair);
}

PairChi2 pairChi2(const KannalaBrandtCamera<double>& lens, const Sim3d& S12, const PointPair& pair) {
  return detail::twoWayChi2(lens, S12, pair);
}

Sim3Estimate estimateSim3Ransac(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera,
                                const Sim3RansacOptions& options, std::mt19937& rng) {
  const auto fit = [&](const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) {
    return alignSim3(source, target, options.fixScale);
  };
  const auto score = [&](const Sim3d& S, std::vector<char>& inliers) {
    return detail::classify(pairs, camera, S, options.inlierChi2, false, inliers);
  };
  const double n = static_cast<double>(pairs.size());
  const auto needed = [&](int best) {
    return best < options.minInliers ? std::numeric_limits<double>::infinity()
                                     : iterationsNeeded(best / n, options.confidence);
  };
  const detail::RansacResult<Sim3d> r =
      detail::ransacOverTriples<Sim3d>(pairs, options.iterations, options.minInliers, rng, fit, fit, score, needed);
  Sim3Estimate out;
  out.found = r.found;
  out.S12 = r.model;
  out.inliers = r.inliers;
  out.inlierCount = r.inlierCount;
  out.iterations = r.iterations;
  return out;
}

int refineSim3(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, Sim3d& S12,
               std::vector<char>& inliers, double outlierChi2) {
  return detail::refineTwoWay<Sim3Problem, optim::MonoSim3Reprojection, optim::MonoInverseSim3Reprojection>(
      pairs, camera, S12, inliers, outlierChi2);
}

int refineSim3(const std::vector<PointPair>& pairs, const KannalaBrandtCamera<double>& lens, Sim3d& S12,
               std::vector<char>& inliers, double outlierChi2) {
  return detail::refineTwoWay<LensSim3Problem, optim::Sim3Reprojection<Lens>, optim::InverseSim3Reprojection<Lens>>(
      pairs, lens, S12, inliers, outlierChi2);
}

}  // namespace orbis::loop
