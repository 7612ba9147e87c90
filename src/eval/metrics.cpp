// ATE, RPE and the KITTI odometry metric; see orbis/eval/metrics.hpp.
#include "orbis/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "orbis/util/error.hpp"

namespace orbis::eval {
namespace {

double rotationAngle(const Eigen::Matrix3d& r) {
  // The KITTI devkit's formula (clamped acos of the trace); the one place it matters, the KITTI
  // metric, must agree with the devkit, and elsewhere it is equally accurate for our purpose.
  const double d = 0.5 * (r.trace() - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

// The error of the estimate's motion from a to b against the ground truth's.
SE3d relativeError(const SE3d& gtA, const SE3d& gtB, const SE3d& estA, const SE3d& estB) {
  return (estA.inverse() * estB).inverse() * (gtA.inverse() * gtB);
}

}  // namespace

ErrorStatistics computeStatistics(const std::vector<double>& errors) {
  ErrorStatistics s;
  s.count = errors.size();
  if (errors.empty()) return s;
  double sum = 0, sumSquares = 0;
  s.min = errors.front();
  s.max = errors.front();
  for (double e : errors) {
    sum += e;
    sumSquares += e * e;
    s.min = std::min(s.min, e);
    s.max = std::max(s.max, e);
  }
  const double n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sumSquares / n);
  double sumDeviation = 0;
  for (double e : errors) sumDeviation += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(sumDeviation / n);
  std::vector<double> sorted = errors;
  const std::size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid), sorted.end());
  s.median = sorted[mid];
  if (sorted.size() % 2 == 0)
    s.median = 0.5 * (s.median +
                      *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid)));
  return s;
}

AteResult computeAte(const Trajectory& groundTruth, const Trajectory& estimate, const AteOptions& options) {
  AteResult result;
  result.pairs = associateByTime(groundTruth, estimate, options.maxDt);
  if (result.pairs.empty())
    throw Error(
        "evaluation", "",
        "no estimated pose lies within " + std::to_string(options.maxDt) + " s of a ground-truth pose");
  result.alignment = alignTrajectories(groundTruth, estimate, result.pairs, options.alignment);
  result.errors.reserve(result.pairs.size());
  result.alignedEstimate.reserve(result.pairs.size());
  for (const PosePair& p : result.pairs) {
    const StampedPose& est = estimate[p.estimate];
    result.alignedEstimate.push_back({est.t, applySimilarity(result.alignment, est.pose)});
    result.errors.push_back(
        (groundTruth[p.groundTruth].pose.translation() - result.alignedEstimate.back().pose.translation())
            .norm());
  }
  result.stats = computeStatistics(result.errors);
  return result;
}

RpeResult computeRpe(const Trajectory& groundTruth, const Trajectory& estimate, const RpeOptions& options) {
  if (!(options.delta > 0)) throw Error("evaluation", "", "the RPE delta must be positive");
  const std::vector<PosePair> pairs = associateByTime(groundTruth, estimate, options.maxDt);
  const Sim3d alignment = alignTrajectories(groundTruth, estimate, pairs, options.alignment);
  std::vector<SE3d> gt, est;
  std::vector<double> times;
  for (const PosePair& p : pairs) {
    gt.push_back(groundTruth[p.groundTruth].pose);
    est.push_back(applySimilarity(alignment, estimate[p.estimate].pose));
    times.push_back(groundTruth[p.groundTruth].t);
  }
  const std::vector<double> distances = trajectoryDistances(gt);

  RpeResult result;
  result.matched = pairs.size();
  for (std::size_t a = 0; a < gt.size(); ++a) {
    std::size_t b = 0;
    if (options.unit == DeltaUnit::Frames) {
      b = a + static_cast<std::size_t>(std::llround(options.delta));
      if (b >= gt.size()) break;
    } else {
      const auto it = std::lower_bound(distances.begin() + static_cast<std::ptrdiff_t>(a), distances.end(),
                                       distances[a] + options.delta);
      if (it == distances.end()) break;
      b = static_cast<std::size_t>(it - distances.begin());
    }
    const SE3d error = relativeError(gt[a], gt[b], est[a], est[b]);
    result.times.push_back(times[a]);
    result.translationErrors.push_back(error.translation().norm());
    result.rotationErrorsDegrees.push_back(rotationAngle(error.rotationMatrix()) * 180.0 / std::numbers::pi);
  }
  if (result.translationErrors.empty())
    throw Error("evaluation", "",
                "no pose pair is " + std::to_string(options.delta) +
                    (options.unit == DeltaUnit::Frames ? " frames" : " m") + " apart among " +
                    std::to_string(pairs.size()) + " matched poses");
  result.translation = computeStatistics(result.translationErrors);
  result.rotationDegrees = computeStatistics(result.rotationErrorsDegrees);
  return result;
}

std::vector<double> trajectoryDistances(const std::vector<SE3d>& poses) {
  std::vector<double> distances(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    distances[i] = distances[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return distances;
}

long lastFrameFromSegmentLength(const std::vector<double>& distances, std::size_t first, double length) {
  for (std::size_t i = first; i < distances.size(); ++i)
    if (distances[i] > distances[first] + length) return static_cast<long>(i);
  return -1;
}

KittiResult computeKittiMetric(const std::vector<SE3d>& groundTruth, const std::vector<SE3d>& estimate,
                               const std::vector<double>& lengths) {
  if (groundTruth.size() != estimate.size())
    throw Error("evaluation", "",
                "the KITTI metric pairs frame for frame; ground truth has " +
                    std::to_string(groundTruth.size()) + " poses, estimate " +
                    std::to_string(estimate.size()));
  constexpr std::size_t kStepSize = 10;  // the devkit evaluates from every 10th frame
  const std::vector<double> distances = trajectoryDistances(groundTruth);
  KittiResult result;
  for (std::size_t first = 0; first < groundTruth.size(); first += kStepSize) {
    for (double length : lengths) {
      const long last = lastFrameFromSegmentLength(distances, first, length);
      if (last < 0) continue;
      const auto lastIndex = static_cast<std::size_t>(last);
      const SE3d error =
          relativeError(groundTruth[first], groundTruth[lastIndex], estimate[first], estimate[lastIndex]);
      const double frames = static_cast<double>(lastIndex - first + 1);
      result.segments.push_back({first, length, error.translation().norm() / length,
                                 rotationAngle(error.rotationMatrix()) / length, length / (0.1 * frames)});
    }
  }
  if (result.segments.empty())
    throw Error("evaluation", "",
                "the ground truth's path (" + std::to_string(std::lround(distances.empty() ? 0.0 : distances.back())) +
                    " m) is shorter than the shortest KITTI segment (" +
                    std::to_string(std::lround(lengths.empty() ? 0.0 : lengths.front())) + " m)");
  constexpr double kRadToDegPer100m = 180.0 / std::numbers::pi * 100.0;
  for (const KittiSegment& s : result.segments) {
    result.translationPercent += s.translationError;
    result.rotationDegPer100m += s.rotationError;
  }
  const double n = static_cast<double>(result.segments.size());
  result.translationPercent *= 100.0 / n;
  result.rotationDegPer100m *= kRadToDegPer100m / n;
  for (double length : lengths) {
    KittiLengthSummary summary{length, 0, 0, 0};
    for (const KittiSegment& s : result.segments) {
      if (s.length != length) continue;
      ++summary.segments;
      summary.translationPercent += s.translationError;
      summary.rotationDegPer100m += s.rotationError;
    }
    if (summary.segments == 0) continue;
    summary.translationPercent *= 100.0 / static_cast<double>(summary.segments);
    summary.rotationDegPer100m *= kRadToDegPer100m / static_cast<double>(summary.segments);
    result.perLength.push_back(summary);
  }
  return result;
}

}  // namespace orbis::eval
