// orbis/eval/alignment.hpp — timestamp association and Umeyama alignment of trajectories.
//
// Contract: associateByTime pairs each estimate pose with at most one ground-truth pose and
// vice versa, nearest timestamps first, within maxDt seconds (inclusive), exactly as the TUM
// benchmark's associate.py does; pairs come back ordered by estimate time. umeyamaAlignment
// returns the similarity S minimising sum ||target_i - S(source_i)||^2 (Umeyama 1991), with the
// scale fixed to 1 unless estimateScale; it needs at least 3 points in general position for a
// unique rotation (fewer, or degenerate input, still returns a valid S — never NaN — and the
// caller sees the degeneracy in the residuals).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "orbis/geometry/sim3.hpp"
#include "orbis/io/trajectory.hpp"

namespace orbis::eval {

// One associated pair of poses: indices into the ground truth and the estimate.
struct PosePair {
  std::size_t groundTruth;  // index into the ground-truth trajectory
  std::size_t estimate;     // index into the estimated trajectory
};

// Pairs each estimate pose with the ground-truth pose nearest in time, one-to-one, within maxDt
// seconds (the TUM benchmark's and evo's association).
std::vector<PosePair> associateByTime(const Trajectory& groundTruth, const Trajectory& estimate,
                                      double maxDt);

// Pairs by index, for trajectories that share frames (KITTI): requires equal sizes.
std::vector<PosePair> associateByIndex(const Trajectory& groundTruth, const Trajectory& estimate);

// How an estimate is aligned to the ground truth before errors are measured: not at all, by a rigid
// motion, or by a similarity (monocular).
enum class Alignment { None, SE3, Sim3 };
// "none", "se3" or "sim3"; throws orbis::Error(source) otherwise.
Alignment parseAlignment(std::string_view name, const std::string& source = "alignment");
// "none", "se3" or "sim3".
std::string_view toString(Alignment alignment);

// source and target are 3xN with the same N (>= 1).
Sim3d umeyamaAlignment(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target, bool estimateScale);

// The alignment of the estimate's positions onto the ground truth's over the given pairs:
// identity for Alignment::None.
Sim3d alignTrajectories(const Trajectory& groundTruth, const Trajectory& estimate,
                        const std::vector<PosePair>& pairs, Alignment alignment);

// S applied to a camera-to-world pose: rotation R_S R, centre S(t). The scale moves the
// camera centre only; orientation stays a rotation.
SE3d applySimilarity(const Sim3d& similarity, const SE3d& pose);

}  // namespace orbis::eval
