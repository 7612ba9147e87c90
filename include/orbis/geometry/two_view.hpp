// orbis/geometry/two_view.hpp — monocular map initialisation from two views (ORB-SLAM §IV,
// the paper's §III "automatic map initialisation" for the monocular case).
//
// Contract: given matched keypoints of two frames in undistorted pixels (each with the σ² of
// its pyramid level in its own view), the pinhole intrinsics K and a seeded generator,
// initialiseTwoView() estimates a homography (normalised DLT) and a fundamental matrix
// (normalised eight-point, rank 2) by RANSAC on the SAME minimal sets, scores both with the
// symmetric transfer error under χ² gates, picks H when R_H = S_H / (S_H + S_F) > 0.45 and F
// otherwise (a narrow H win whose motion is ambiguous falls back to F's, see
// fundamentalFallbackRatio), refits the winner on its inliers, recovers the motion (Faugeras' eight
// homography solutions, or the four (R, t) of E = KᵀFK), triangulates every inlier under each
// candidate motion with the cheirality, parallax and reprojection checks, and refines the best
// motion on the Sampson distance (the linear fits are biased for sideways motion). It accepts only
// a clear winner with enough well-triangulated points and enough parallax; otherwise it
// refuses with a TwoViewRefusal saying why (the caller waits for a later frame).
// Motion convention: x₂ = R·x₁ + t (frame-1 coordinates to frame 2), ‖t‖ = 1; points are in
// frame 1. The result depends only on the input and the generator's state (no clocks; F's
// RANSAC may run on a second thread, whose timing changes nothing): the same seed gives the
// same bits. Nothing throws (without a thread to be had, both RANSACs run on the caller's).
#pragma once

#include <cstdint>
#include <random>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace orbis {

// A keypoint match between the two views of an initialisation, with each keypoint's level σ².
struct TwoViewMatch {
  // @{
  // Undistorted pixels in view 1 and view 2.
  Eigen::Vector2d first, second;       // undistorted pixels in view 1 and view 2
  // @}
  // @{
  // σ² of each keypoint's pyramid level (px²).
  double sigma2First = 1, sigma2Second = 1;  // σ² of each keypoint's pyramid level (px²)
  // @}
};

// The two-view model a motion was recovered from: a homography (planar or low-parallax scene) or a
// fundamental matrix.
enum class TwoViewModel : std::uint8_t { Homography, Fundamental };

// Why an initialisation attempt was refused (None: accepted).
enum class TwoViewRefusal : std::uint8_t {
  None,                // accepted
  TooFewMatches,       // fewer than a minimal set (8), or fewer than minTriangulated
  TooFewInliers,       // the chosen model explains fewer than minTriangulated matches
  LowParallax,         // the best motion sees its points under less than minParallaxDeg:
                       // a static camera, a pure rotation, or a translation too small yet
  TooFewTriangulated,  // the best motion triangulates too few points (< 90% of the inliers)
  Ambiguous,           // a second motion hypothesis explains nearly as many points
};

// @{
// The model's or refusal's name, as reports print it.
std::string_view toString(TwoViewModel model);
std::string_view toString(TwoViewRefusal refusal);
// @}

// Thresholds of the two-view initialiser (ORB-SLAM's unless noted).
struct TwoViewOptions {
  int ransacIterations = 200;       // ORB-SLAM's; each draws one 8-point set used by H and F
  double homographyRatioThreshold = 0.45;  // choose H when R_H exceeds this
  // H won by a margin too narrow to trust (R_H at most this) and its reconstruction is
  // ambiguous: F's reconstruction is tried and kept if accepted. ORB-SLAM3 chooses H only
  // above 0.50; below, any scene seen under little parallax is nearly a homography, so H wins
  // ties and its plane ambiguity refuses frame after frame (rendered 320x240 loops: 16-73
  // frames). 0 turns the fallback off (the paper's rule alone).
  double fundamentalFallbackRatio = 0.5;
  // The best motion must see its points under at least this parallax (degrees).
  double minParallaxDeg = 1.0;
  // Points the best motion must triangulate.
  int minTriangulated = 50;
  double minGoodFractionOfInliers = 0.9;  // the winner triangulates at least this share
  double maxSecondBestRatio = 0.75;       // the runner-up must stay below this × the winner
  bool refitOnInliers = true;             // least squares on all inliers after RANSAC
  bool refineMotion = true;  // the winning motion refined on the Sampson distance of the inliers
  bool parallelModels = true;  // F's RANSAC on a second thread (same result either way)
};

// The outcome of an initialisation attempt: the motion and points when accepted, why not otherwise.
struct TwoViewResult {
  // Why refused (None: accepted).
  TwoViewRefusal refusal = TwoViewRefusal::TooFewMatches;
  // The model the motion came from.
  TwoViewModel model = TwoViewModel::Fundamental;
  double homographyRatio = 0;  // R_H = S_H / (S_H + S_F)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // R: frame 1 -> frame 2
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // t, unit norm when accepted
  // @{
  // Per match when accepted, empty when refused: the point in frame 1 (meaningful where
  // triangulated) and whether it passed every check under enough parallax to trust its depth.
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> triangulated;
  // @}
  int inliers = 0;        // matches inside the chosen model's χ² gates
  int goodPoints = 0;     // the best motion's points passing cheirality and reprojection
  int secondBestGood = 0; // the runner-up motion's
  double parallaxDeg = 0; // the best motion's parallax (ORB-SLAM's: the 51st largest angle)

  // Whether the attempt was accepted.
  bool accepted() const { return refusal == TwoViewRefusal::None; }
};

// K: the pinhole intrinsics [fx 0 cx; 0 fy cy; 0 0 1] the pixels are in.
TwoViewResult initialiseTwoView(std::span<const TwoViewMatch> matches, const Eigen::Matrix3d& K,
                                std::mt19937& rng, const TwoViewOptions& options = {});

}  // namespace orbis
