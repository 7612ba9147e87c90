// orbis/loop/relative_pose.hpp — the rigid transform between two keyframes from matched map
// points, for loop closing with metric sensors (stereo, RGB-D: paper §III-D, SE(3) not Sim(3)).
//
// Contract: a PointPair holds one matched map point expressed in each camera (p1 in keyframe 1,
// p2 in keyframe 2) and the keypoint it was observed at in each image, with the information
// 1/σ² of the keypoint's pyramid level. T12 maps camera-2 coordinates into camera 1.
// Both keyframes share the sensor's camera; projections go through its pinhole.
//  - estimateRelativePoseRansac: minimal 3-point closed-form solutions (Horn/Umeyama) on random
//    triples drawn from the caller's generator; a pair is an inlier when it reprojects within
//    χ²(2 dof, 99%) = 9.21 σ² in both images. Returns the best hypothesis re-estimated from all
//    its inliers, `found` only with at least minInliers inliers.
//  - refineRelativePose: the two-way reprojection error (optim::MonoReprojection into camera 1,
//    optim::InversePoseReprojection into camera 2, Huber kernel at `outlierChi2`) minimised by
//    the library's Levenberg–Marquardt (optim::Problem) over T12 with the points fixed, twice,
//    dropping after the first round the pairs whose χ² in either image exceeds `outlierChi2`;
//    returns the inliers left. Same inputs, same output, bit for bit.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/se3.hpp"

namespace orbis::loop {

// A map point matched between two keyframes: its position in each camera, its keypoints and their
// weights.
struct PointPair {
  // @{
  // The point in camera 1 and in camera 2.
  Eigen::Vector3d p1, p2;      // the point in camera 1 and in camera 2
  // @}
  // @{
  // Its keypoints (undistorted pixels).
  Eigen::Vector2d obs1, obs2;  // its keypoints (undistorted pixels)
  // @}
  // @{
  // 1/σ² of each keypoint.
  double information1 = 1, information2 = 1;
  // @}
};

// A pair's χ² (information·‖π(T12·p2) − obs1‖², and the same for π(T12⁻¹·p1) against obs2);
// not valid when the point falls behind either camera.
struct PairChi2 {
  // @{
  // The χ² in image 1 and image 2.
  double chi2First = 0, chi2Second = 0;
  // @}
  // False when the point falls behind either camera.
  bool valid = false;
};
// The pair's χ² in each image through T12.
PairChi2 pairChi2(const PinholeCamera<double>& camera, const SE3d& T12, const PointPair& pair);

// The metric loop's RANSAC over relative poses.
struct RelativePoseRansacOptions {
  // @{
  // Hypotheses, inliers required, and the χ² gate (99 %, 2 dof).
  int iterations = 300;
  int minInliers = 20;
  double inlierChi2 = 9.21;
  // @}
};

// A verified relative pose between two keyframes.
struct RelativePoseEstimate {
  // @{
  // Whether one was found, the pose, and which pairs agree with it.
  bool found = false;
  SE3d T12;
  std::vector<char> inliers;
  int inlierCount = 0;
  // @}
};

// RANSAC over three-point rigid fits (Horn), scored by χ² in both images.
RelativePoseEstimate estimateRelativePoseRansac(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera,
                                                const RelativePoseRansacOptions& options, std::mt19937& rng);

// Refines T12 over the pairs flagged in `inliers` and rewrites the flags.
int refineRelativePose(const std::vector<PointPair>& pairs, const PinholeCamera<double>& camera, SE3d& T12,
                       std::vector<char>& inliers, double outlierChi2 = 10.0);

// Closed-form least-squares rigid transform with target ≈ T·source (Umeyama, scale 1).
SE3d alignPoints(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target);

}  // namespace orbis::loop
