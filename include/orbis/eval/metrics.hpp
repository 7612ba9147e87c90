// orbis/eval/metrics.hpp — trajectory error metrics: ATE, RPE and the KITTI odometry metric.
//
// Contract:
//  - computeAte: associate by time (maxDt), align the estimate's positions onto the ground
//    truth (SE(3) for metric sensors, Sim(3) for monocular, or none), and report statistics of
//    the per-pose position error in metres, as the TUM benchmark and evo define ATE.
//  - computeRpe: on the associated (and aligned, if asked; only Sim(3)'s scale matters) poses,
//    the error of the relative motion between pose i and pose j, where j = i + delta frames,
//    or the first pose whose ground-truth path length from i reaches delta metres. Translation
//    part in metres, rotation part in degrees.
//  - computeKittiMetric: the KITTI devkit's evaluate_odometry on one sequence — from every 10th
//    frame, segments of 100, 200, ..., 800 m of ground-truth path length; t_rel is the mean of
//    translation error / length (reported in %), r_rel the mean of rotation angle / length
//    (reported in deg per 100 m). Pairs are frame-for-frame (devkit semantics).
// Throws orbis::Error("evaluation") when nothing can be evaluated (no matched pose, no segment).
#pragma once

#include <cstddef>
#include <vector>

#include "orbis/eval/alignment.hpp"

namespace orbis::eval {

// Statistics of a set of errors.
struct ErrorStatistics {
  // @{
  // Root mean square, mean, median, largest, smallest and standard deviation.
  double rmse = 0, mean = 0, median = 0, max = 0, min = 0, std = 0;
  // @}
  // How many errors.
  std::size_t count = 0;
};
// Population standard deviation, as numpy/evo compute it; all zero for an empty input.
ErrorStatistics computeStatistics(const std::vector<double>& errors);

// How to associate and align for the absolute trajectory error.
struct AteOptions {
  // The alignment of the estimate onto the ground truth.
  Alignment alignment = Alignment::SE3;
  double maxDt = 0.02;  // seconds
};
// The absolute trajectory error (ATE) and what it was computed from.
struct AteResult {
  ErrorStatistics stats;        // metres
  Sim3d alignment;              // maps estimate world → ground-truth world
  std::vector<PosePair> pairs;  // matched poses
  std::vector<double> errors;   // per pair, metres
  Trajectory alignedEstimate;   // the matched estimate poses after alignment
};
// Absolute trajectory error: associate by time (maxDt), align the estimate's positions onto the
// ground truth (Umeyama), and measure the remaining position errors.
AteResult computeAte(const Trajectory& groundTruth, const Trajectory& estimate,
                     const AteOptions& options = {});

// The unit of the relative pose error's pair distance.
enum class DeltaUnit { Frames, Metres };
// How relative pose error pairs are drawn and associated.
struct RpeOptions {
  // Distance between the two poses of a pair.
  double delta = 1.0;
  // In frames or metres of ground-truth path.
  DeltaUnit unit = DeltaUnit::Frames;
  // Alignment before measuring (only Sim(3)'s scale matters for RPE).
  Alignment alignment = Alignment::None;
  // Largest timestamp difference of an associated pair, seconds.
  double maxDt = 0.02;
};
// The relative pose error (RPE) in translation and rotation.
struct RpeResult {
  ErrorStatistics translation;  // metres
  // Rotation errors, degrees.
  ErrorStatistics rotationDegrees;
  std::vector<double> times;  // ground-truth time of the pair's first pose
  // @{
  // Per-pair translation (metres) and rotation (degrees) errors.
  std::vector<double> translationErrors;
  std::vector<double> rotationErrorsDegrees;
  // @}
  std::size_t matched = 0;  // associated poses the pairs were drawn from
};
// Relative pose error over pose pairs delta apart, as the TUM benchmark and evo compute it.
RpeResult computeRpe(const Trajectory& groundTruth, const Trajectory& estimate,
                     const RpeOptions& options = {});

// One KITTI devkit segment: its first frame, length, errors and speed.
struct KittiSegment {
  // The frame the segment starts at.
  std::size_t firstFrame = 0;
  double length = 0;            // metres
  double translationError = 0;  // ratio (metres per metre)
  double rotationError = 0;     // radians per metre
  double speed = 0;             // metres per second at KITTI's 10 Hz
};
// The KITTI errors averaged over the segments of one length.
struct KittiLengthSummary {
  // @{
  // Segment length (m), segments of that length, translation error (%) and rotation error (deg/100
  // m).
  double length = 0;
  std::size_t segments = 0;
  double translationPercent = 0;
  double rotationDegPer100m = 0;
  // @}
};
// The KITTI odometry metric: translation (%) and rotation (deg/100 m) errors over 100–800 m
// segments.
struct KittiResult {
  double translationPercent = 0;  // t_rel
  double rotationDegPer100m = 0;  // r_rel
  // Every segment measured.
  std::vector<KittiSegment> segments;
  std::vector<KittiLengthSummary> perLength;  // only lengths that have segments
};
// groundTruth and estimate are frame-for-frame (same size); lengths default to the devkit's.
KittiResult computeKittiMetric(const std::vector<SE3d>& groundTruth, const std::vector<SE3d>& estimate,
                               const std::vector<double>& lengths = {100, 200, 300, 400, 500, 600, 700, 800});

// KITTI devkit helpers, exposed for tests: cumulative path length, and the last frame of the
// segment starting at `first` (the first frame whose distance exceeds dist[first] + length),
// or -1 when the trajectory is too short.
std::vector<double> trajectoryDistances(const std::vector<SE3d>& poses);
// The last frame of the segment starting at first, or −1 when the trajectory is too short.
long lastFrameFromSegmentLength(const std::vector<double>& distances, std::size_t first, double length);

}  // namespace orbis::eval
