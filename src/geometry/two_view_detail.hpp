// Internal pieces of the two-view initialiser (include/orbis/geometry/two_view.hpp): model
// fitting and scoring (two_view_models.cpp), motion recovery and its checks
// (two_view_motion.cpp). Not installed; the public contract is the one of two_view.hpp.
#pragma once

#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>  // homogeneous(), hnormalized()

#include "orbis/geometry/two_view.hpp"

namespace orbis::two_view_detail {

inline constexpr int kSampleSize = 8;  // the eight-point algorithm's; H uses the same set
using SampleSet = std::array<int, kSampleSize>;

// Hartley's normalisation, one transform per view over all matches (ORB-SLAM's variant: mean
// absolute deviation 1 per axis), so every RANSAC set and the refit share it.
struct NormalisedMatches {
  std::vector<Eigen::Vector2d> first, second;
  Eigen::Matrix3d firstTransform, secondTransform;  // pixel -> normalised, per view
};
NormalisedMatches normaliseMatches(std::span<const TwoViewMatch> matches);

// Both return the model in pixels, mapping view 1 to view 2 (x₂ ~ H·x₁, x₂ᵀ·F·x₁ = 0), from
// the matches whose indices are given (at least 4 for H, 8 for F).
Eigen::Matrix3d fitHomography(const NormalisedMatches& normalised, std::span<const int> indices);
Eigen::Matrix3d fitFundamental(const NormalisedMatches& normalised, std::span<const int> indices);

struct ModelScore {
  double score = 0;          // Σ over both sides of (th_score − χ²) for gated sides
  std::vector<bool> inliers;  // per match: inside the gate on both sides
  int inlierCount = 0;
};
ModelScore scoreHomography(const Eigen::Matrix3d& H21, std::span<const TwoViewMatch> matches);
ModelScore scoreFundamental(const Eigen::Matrix3d& F21, std::span<const TwoViewMatch> matches);

struct MotionHypothesis {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;  // unit norm
};
// Faugeras' decomposition: eight motions, or none when two singular values of K⁻¹HK coincide
// (a pure rotation or no motion at all: no translation can be recovered).
std::vector<MotionHypothesis> homographyMotions(const Eigen::Matrix3d& H21, const Eigen::Matrix3d& K);
// E = KᵀFK = U·diag(1,1,0)·Vᵀ: the four combinations of two rotations and ±t.
std::vector<MotionHypothesis> essentialMotions(const Eigen::Matrix3d& F21, const Eigen::Matrix3d& K);

struct MotionCheck {
  int good = 0;            // inliers passing cheirality and reprojection
  double parallaxDeg = 0;  // the 51st largest parallax among them (ORB-SLAM's measure)
  std::vector<Eigen::Vector3d> points;  // per match, frame 1
  std::vector<bool> triangulated;       // good and seen under enough parallax to trust depth
};
MotionCheck checkMotion(const MotionHypothesis& motion, std::span<const TwoViewMatch> matches,
                        const std::vector<bool>& inliers, const Eigen::Matrix3d& K);

// Levenberg–Marquardt on the Sampson distance of the inliers over (R, unit t), from `start`
// (two_view_refine.cpp): the linear fits' algebraic error is biased, this is close to the
// maximum-likelihood motion.
MotionHypothesis refineMotion(const MotionHypothesis& start, std::span<const TwoViewMatch> matches,
                              const std::vector<bool>& inliers, const Eigen::Matrix3d& K, int iterations = 20);

// F = K⁻ᵀ·[t]ₓ·R·K⁻¹: the epipolar geometry a motion implies, in pixels.
Eigen::Matrix3d fundamentalOf(const MotionHypothesis& motion, const Eigen::Matrix3d& K);

}  // namespace orbis::two_view_detail
