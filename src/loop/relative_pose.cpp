#include "orbis/loop/relative_pose.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "orbis/optim/problem.hpp"
#include "orbis/optim/reprojection.hpp"

namespace orbis::loop {

namespace {

using RelativePoseProblem =
    optim::Problem<optim::SE3Manifold, optim::Term<optim::MonoReprojection, optim::HuberKernel>,
                   optim::Term<optim::InversePoseReprojection<PinholeCamera<double>>, optim::HuberKernel>>;

// Flags the pairs within `chi2` in both images (only among those already flagged when
// `keepOutliersOut`); returns how many.
int classify(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, const SE3d& T12, double chi2,
             bool keepOutliersOut, std::vector<char>& inliers) {
  int count = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (keepOutliersOut && !inliers[k]) continue;
    const PairChi2 c = pairChi2(camera, T12, pairs[k]);
    inliers[k] = c.valid && c.chi2First < chi2 && c.chi2Second < chi2;
    count += inliers[k];
  }
  return count;
}

// Levenberg–Marquardt over T12 on the flagged pairs, Huber at √huberChi2 σ, points fixed.
void refineOnFlagged(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, SE3d& T12,
                     const std::vector<char>& use, double huberChi2, int iterations) {
  RelativePoseProblem problem;
  problem.addPose(T12);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!use[k]) continue;
    const PointPair& pair = pairs[k];
    const int inCamera2 = problem.addPoint(pair.p2, /*fixed=*/true);
    problem.add(optim::MonoReprojection{pair.obs1, &camera}, 0, inCamera2, pair.information1, huberChi2);
    const int inCamera1 = problem.addPoint(pair.p1, /*fixed=*/true);
    problem.add(optim::InversePoseReprojection<PinholeCamera<double>>{pair.obs2, &camera}, 0, inCamera1,
                pair.information2, huberChi2);
  }
  if (problem.numPoints() == 0) return;
  optim::SolverOptions options;
  options.maxIterations = iterations;
  options.linearSolver = optim::LinearSolverKind::DenseCholesky;
  problem.solve(options);
  T12 = problem.pose(0);
}

}  // namespace

PairChi2 pairChi2(const PinholeCamera<double>& camera, const SE3d& T12, const PointPair& pair) {
  const Eigen::Vector3d q1 = T12 * pair.p2;            // point 2 seen by camera 1
  const Eigen::Vector3d q2 = T12.inverse() * pair.p1;  // point 1 seen by camera 2
  PairChi2 out;
  if (!PinholeCamera<double>::inFront(q1) || !PinholeCamera<double>::inFront(q2)) return out;
  out.chi2First = (camera.project(q1) - pair.obs1).squaredNorm() * pair.information1;
  out.chi2Second = (camera.project(q2) - pair.obs2).squaredNorm() * pair.information2;
  out.valid = true;
  return out;
}

SE3d alignPoints(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) {
  const Eigen::Matrix4d T = Eigen::umeyama(source, target, false);
  return SE3d::fromMatrix(T);
}

RelativePoseEstimate estimateRelativePoseRansac(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera,
                                                const RelativePoseRansacOptions& options, std::mt19937& rng) {
  RelativePoseEstimate best;
  const std::size_t n = pairs.size();
  if (n < 3 || static_cast<int>(n) < options.minInliers) return best;
  std::vector<char> inliers(n);
  for (int it = 0; it < options.iterations; ++it) {
    // Three distinct indices; rng() % n keeps the draw identical on every standard library.
    std::size_t idx[3];
    idx[0] = rng() % n;
    do idx[1] = rng() % n; while (idx[1] == idx[0]);
    do idx[2] = rng() % n; while (idx[2] == idx[0] || idx[2] == idx[1]);
    Eigen::Matrix3d source, target;
    for (int c = 0; c < 3; ++c) {
      source.col(c) = pairs[idx[c]].p2;
      target.col(c) = pairs[idx[c]].p1;
    }
    // A degenerate (near-collinear) triple gives no rotation.
    const Eigen::Vector3d e1 = source.col(1) - source.col(0), e2 = source.col(2) - source.col(0);
    if (e1.cross(e2).norm() < 1e-6 * e1.norm() * e2.norm() + 1e-12) continue;
    const SE3d T = alignPoints(source, target);
    const int count = classify(pairs, camera, T, options.inlierChi2, false, inliers);
    if (count > best.inlierCount) {
      best.inlierCount = count;
      best.T12 = T;
      best.inliers = inliers;
    }
  }
  if (best.inlierCount < options.minInliers || best.inlierCount < 3) return RelativePoseEstimate{};
  // Re-estimate from every inlier, then re-classify.
  Eigen::Matrix3Xd source(3, best.inlierCount), target(3, best.inlierCount);
  for (std::size_t k = 0, c = 0; k < n; ++k) {
    if (!best.inliers[k]) continue;
    source.col(static_cast<long>(c)) = pairs[k].p2;
    target.col(static_cast<long>(c)) = pairs[k].p1;
    ++c;
  }
  const SE3d refined = alignPoints(source, target);
  const int count = classify(pairs, camera, refined, options.inlierChi2, false, inliers);
  if (count >= best.inlierCount) {
    best.T12 = refined;
    best.inliers = inliers;
    best.inlierCount = count;
  }
  best.found = true;
  return best;
}

int refineRelativePose(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, SE3d& T12,
                       std::vector<char>& inliers, double outlierChi2) {
  inliers.resize(pairs.size(), 0);
  refineOnFlagged(pairs, camera, T12, inliers, outlierChi2, 5);
  if (classify(pairs, camera, T12, outlierChi2, true, inliers) >= 3)
    refineOnFlagged(pairs, camera, T12, inliers, outlierChi2, 10);
  return classify(pairs, camera, T12, outlierChi2, true, inliers);
}

}  // namespace orbis::loop
