// orbis/loop/sim3_solver.hpp — the similarity between two keyframes of a monocular map from
// matched map points (paper §III-D; ORB-SLAM §VII-B): a monocular map drifts in scale as well as
// in pose, so a loop is a Sim(3), not an SE(3).
//
// Contract: pairs are loop::PointPair (relative_pose.hpp): one matched map point expressed in
// each camera (p1 in keyframe 1, p2 in keyframe 2) with its keypoint in each image and the
// information 1/σ² of the keypoint's pyramid level. S12 maps camera-2 coordinates, at keyframe
// 2's map scale, into camera 1: p1 ≈ s·R·p2 + t. Both keyframes share the sensor's pinhole.
//  - alignSim3: Horn's closed form (unit quaternion from the 4×4 symmetric matrix of the
//    centred cross-covariance, then the least-squares scale and the translation), with the scale
//    optionally fixed to 1; refuses (nullopt) fewer than 3 points and point sets that do not fix
//    a rotation (collinear or coincident on either side).
//  - estimateSim3Ransac: minimal 3-pair solutions on triples drawn as `rng() % n` from the
//    caller's generator (same generator state, same result, on every standard library); a pair is
//    an inlier when it reprojects within inlierChi2 (χ² 2 dof 99%: 9.21) of its keypoint, in units
//    of its level's σ², in both images. Stops after `iterations`, or earlier once the best
//    hypothesis makes a better one improbable (probability `confidence`). The best hypothesis is
//    re-estimated from all its inliers (kept if it loses none); `found` only with ≥ minInliers.
//  - refineSim3: the two-way reprojection error (optim::Sim3Reprojection into camera 1,
//    optim::InverseSim3Reprojection into camera 2, Huber at √outlierChi2 σ) minimised by the
//    library's Levenberg–Marquardt over S12 with the points fixed, twice, dropping after the first
//    round the pairs whose χ² exceeds outlierChi2 in either image; returns the inliers left.
//    Bit-identical for identical inputs. Its fisheye overload takes the pairs' keypoints in the
//    lens's pixels and projects through the lens (the MonocularFisheye sensor's loops).
#pragma once

#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/loop/relative_pose.hpp"

namespace orbis::loop {

// target ≈ S·source. Columns are points; both matrices have the same number of columns.
std::optional<Sim3d> alignSim3(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target, bool fixScale = false);

// A pair's χ² in each image through S12 (see PairChi2); not valid behind either camera.
PairChi2 pairChi2(const PinholeCamera<double>& camera, const Sim3d& S12, const PointPair& pair);
// The same through a fisheye lens, the pair's keypoints in its pixels.
PairChi2 pairChi2(const KannalaBrandtCamera<double>& lens, const Sim3d& S12, const PointPair& pair);

// The Sim(3) RANSAC of loop detection (ORB-SLAM2's Sim3Solver).
struct Sim3RansacOptions {
  int iterations = 300;     // ORB-SLAM2's cap
  // @{
  // Inliers required and the χ² gate (99 %, 2 dof).
  int minInliers = 20;
  double inlierChi2 = 9.21;
  // @}
  double confidence = 0.99;  // early stop: P(a better hypothesis exists) below 1 − confidence
  bool fixScale = false;     // true: a rigid motion (a metric sensor's loop)
};

// A verified similarity between two keyframes.
struct Sim3Estimate {
  // @{
  // Whether one was found, the similarity, and which pairs agree with it.
  bool found = false;
  Sim3d S12;
  std::vector<char> inliers;
  int inlierCount = 0;
  // @}
  int iterations = 0;  // hypotheses drawn
};

// RANSAC over three-point similarity fits (Horn), scored by χ² in both images.
Sim3Estimate estimateSim3Ransac(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera,
                                const Sim3RansacOptions& options, std::mt19937& rng);

// Refines S12 over the pairs flagged in `inliers` and rewrites the flags.
int refineSim3(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, Sim3d& S12,
               std::vector<char>& inliers, double outlierChi2 = 10.0);
// The same through a fisheye lens, the pairs' keypoints in its pixels.
int refineSim3(const std::vector<PointPair>& pairs, const KannalaBrandtCamera<double>& lens, Sim3d& S12,
               std::vector<char>& inliers, double outlierChi2 = 10.0);

}  // namespace orbis::loop
