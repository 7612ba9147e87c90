// src/loop/two_way_fit.hpp — what the SE(3) and the Sim(3) loop transforms share: RANSAC over
// 3-pair closed forms and the two-way reprojection refinement, generic over the transform.
//
// Contract (private to src/loop/): a Transform is SE3d or Sim3d with a pairChi2(camera, T, pair)
// overload, the camera a pinhole (or, for the Sim(3) refinement, a fisheye lens, the pairs'
// keypoints then in its pixels); the pairs and their meaning are relative_pose.hpp's. ransacOverTriples draws three
// distinct indices per hypothesis as rng() % n (identical on every standard library), fits them
// with fitTriple (nullopt: degenerate, skipped), counts inliers with `score`, stops after
// `iterations` or once `needed(bestCount)` hypotheses have been drawn, then refits the best
// hypothesis on all its inliers with fitAll and keeps the refit if it loses none.
// refineTwoWay runs the library's LM on `Problem` (one pose, fixed points, the Direct residual
// into camera 1 and the Inverse residual into camera 2, Huber at √outlierChi2 σ): 5 iterations,
// the pairs beyond outlierChi2 in either image dropped, 10 more, and returns the inliers left.
#pragma once

#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "orbis/loop/relative_pose.hpp"
#include "orbis/optim/problem.hpp"

namespace orbis::loop::detail {

// The pair's χ² in camera 1 (its point 2 through T) and in camera 2 (its point 1 through T⁻¹).
template <class Camera, class Transform>
PairChi2 twoWayChi2(const Camera& camera, const Transform& T12, const PointPair& pair) {
  const Eigen::Vector3d q1 = T12 * pair.p2;            // point 2 seen by camera 1
  const Eigen::Vector3d q2 = T12.inverse() * pair.p1;  // point 1 seen by camera 2
  PairChi2 out;
  if (!Camera::inFront(q1) || !Camera::inFront(q2)) return out;
  out.chi2First = (camera.project(q1) - pair.obs1).squaredNorm() * pair.information1;
  out.chi2Second = (camera.project(q2) - pair.obs2).squaredNorm() * pair.information2;
  out.valid = true;
  return out;
}

// Flags the pairs within `chi2` in both images (only among those already flagged when
// `keepOutliersOut`); returns how many.
template <class Camera, class Transform>
int classify(const std::vector<PointPair>& pairs, const Camera& camera, const Transform& T, double chi2,
             bool keepOutliersOut, std::vector<char>& inliers) {
  int count = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (keepOutliersOut && !inliers[k]) continue;
    const PairChi2 c = pairChi2(camera, T, pairs[k]);
    inliers[k] = c.valid && c.chi2First < chi2 && c.chi2Second < chi2;
    count += inliers[k];
  }
  return count;
}

template <class Transform>
struct RansacResult {
  bool found = false;
  Transform model;
  std::vector<char> inliers;
  int inlierCount = 0;
  int iterations = 0;
};

template <class Transform, class FitTriple, class FitAll, class Score, class Needed>
RansacResult<Transform> ransacOverTriples(const std::vector<PointPair>& pairs, int iterations, int minInliers,
                                          std::mt19937& rng, FitTriple fitTriple, FitAll fitAll, Score score,
                                          Needed needed) {
  RansacResult<Transform> best;
  const std::size_t n = pairs.size();
  if (n < 3 || static_cast<int>(n) < minInliers) return best;
  std::vector<char> inliers(n);
  double stopAfter = needed(0);
  int it = 0;
  for (; it < iterations && it < stopAfter; ++it) {
    std::size_t idx[3];
    idx[0] = rng() % n;
    do idx[1] = rng() % n; while (idx[1] == idx[0]);
    do idx[2] = rng() % n; while (idx[2] == idx[0] || idx[2] == idx[1]);
    Eigen::Matrix3d source, target;
    for (int c = 0; c < 3; ++c) {
      source.col(c) = pairs[idx[c]].p2;
      target.col(c) = pairs[idx[c]].p1;
    }
    const std::optional<Transform> T = fitTriple(source, target);
    if (!T) continue;
    const int count = score(*T, inliers);
    if (count > best.inlierCount) {
      best.inlierCount = count;
      best.model = *T;
      best.inliers = inliers;
      stopAfter = needed(count);
    }
  }
  if (best.inlierCount < minInliers || best.inlierCount < 3) {
    RansacResult<Transform> none;
    none.iterations = it;
    return none;
  }
  best.iterations = it;
  Eigen::Matrix3Xd source(3, best.inlierCount), target(3, best.inlierCount);
  for (std::size_t k = 0, c = 0; k < n; ++k) {
    if (!best.inliers[k]) continue;
    source.col(static_cast<long>(c)) = pairs[k].p2;
    target.col(static_cast<long>(c)) = pairs[k].p1;
    ++c;
  }
  if (const std::optional<Transform> refit = fitAll(source, target)) {
    const int count = score(*refit, inliers);
    if (count >= best.inlierCount) {
      best.model = *refit;
      best.inliers = inliers;
      best.inlierCount = count;
    }
  }
  best.found = true;
  return best;
}

template <class Problem, class Direct, class Inverse, class Camera, class Transform>
void refineOnFlagged(const std::vector<PointPair>& pairs, const Camera& camera, Transform& T,
                     const std::vector<char>& use, double huberChi2, int iterations) {
  Problem problem;
  problem.addPose(T);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!use[k]) continue;
    const PointPair& pair = pairs[k];
    const int inCamera2 = problem.addPoint(pair.p2, /*fixed=*/true);
    problem.add(Direct{pair.obs1, &camera}, 0, inCamera2, pair.information1, huberChi2);
    const int inCamera1 = problem.addPoint(pair.p1, /*fixed=*/true);
    problem.add(Inverse{pair.obs2, &camera}, 0, inCamera1, pair.information2, huberChi2);
  }
  if (problem.numPoints() == 0) return;
  optim::SolverOptions options;
  options.maxIterations = iterations;
  options.linearSolver = optim::LinearSolverKind::DenseCholesky;
  problem.solve(options);
  T = problem.pose(0);
}

template <class Problem, class Direct, class Inverse, class Camera, class Transform>
int refineTwoWay(const std::vector<PointPair>& pairs, const Camera& camera, Transform& T,
                 std::vector<char>& inliers, double outlierChi2) {
  inliers.resize(pairs.size(), 0);
  refineOnFlagged<Problem, Direct, Inverse>(pairs, camera, T, inliers, outlierChi2, 5);
  if (classify(pairs, camera, T, outlierChi2, true, inliers) >= 3)
    refineOnFlagged<Problem, Direct, Inverse>(pairs, camera, T, inliers, outlierChi2, 10);
  return classify(pairs, camera, T, outlierChi2, true, inliers);
}

}  // namespace orbis::loop::detail
