// RPE and the KITTI odometry metric on synthetic trajectories with a known, constant drift.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "orbis/eval/metrics.hpp"
#include "orbis/util/error.hpp"

namespace {

using orbis::SE3d;
using orbis::SO3d;
using orbis::Trajectory;
namespace eval = orbis::eval;

// A wavy 3-D path at 10 Hz, and an estimate whose every step carries the same extra motion
// `drift` (in the camera frame): est_{i+1} = est_i (gt_i^-1 gt_{i+1}) drift.
struct Drifted {
  Trajectory gt, est;
};
Drifted drifted(std::size_t n, const SE3d& drift) {
  Drifted d;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.1 * static_cast<double>(i);
    const SE3d pose(SO3d::exp(Eigen::Vector3d(0.05 * std::sin(t), 0.3 * t, 0.02)),
                    Eigen::Vector3d(std::sin(t), 0.2 * t, std::cos(0.5 * t)));
    d.gt.push_back({t, pose});
    const SE3d est = i == 0 ? pose : d.est.back().pose * (d.gt[i - 1].pose.inverse() * pose) * drift;
    d.est.push_back({t, est});
  }
  return d;
}

TEST(Rpe, ConstantDriftPerFrameIsTheRelativeError) {
  const SE3d drift(SO3d::exp(Eigen::Vector3d(0.0, 0.002, 0.001)), Eigen::Vector3d(0.003, -0.001, 0.002));
  const Drifted d = drifted(300, drift);
  const eval::RpeResult rpe = eval::computeRpe(d.gt, d.est, {});
  EXPECT_EQ(rpe.matched, 300u);
  EXPECT_EQ(rpe.translation.count, 299u);
  // The error of one step is drift^-1: its translation has the drift's length, its angle too.
  EXPECT_NEAR(rpe.translation.min, drift.translation().norm(), 1e-9);
  EXPECT_NEAR(rpe.translation.max, drift.translation().norm(), 1e-9);
  EXPECT_NEAR(rpe.rotationDegrees.rmse, drift.so3().log().norm() * 180.0 / std::numbers::pi, 1e-6);

  const eval::RpeResult itself = eval::computeRpe(d.gt, d.gt, {});
  EXPECT_LT(itself.translation.max, 1e-12);
  EXPECT_LT(itself.rotationDegrees.max, 1e-5);  // acos near 1 loses half the digits
}

TEST(Rpe, DeltaInFramesAndMetres) {
  const SE3d drift(SO3d(), Eigen::Vector3d(0.01, 0.0, 0.0));
  const Drifted d = drifted(200, drift);
  eval::RpeOptions frames;
  frames.delta = 5;
  const eval::RpeResult byFrames = eval::computeRpe(d.gt, d.est, frames);
  EXPECT_EQ(byFrames.translation.count, 195u);
  // Pure translational drift without rotation accumulates linearly: 5 steps, 5 drifts, rotated
  // by the intermediate motions, so at most 5 x 0.01 m.
  EXPECT_LE(byFrames.translation.max, 0.05 + 1e-12);
  EXPECT_GT(byFrames.translation.min, 0.01);

  eval::RpeOptions metres;
  metres.delta = 1.0;
  metres.unit = eval::DeltaUnit::Metres;
  const eval::RpeResult byMetres = eval::computeRpe(d.gt, d.est, metres);
  EXPECT_GT(byMetres.translation.count, 0u);
  EXPECT_LT(byMetres.translation.count, 200u);
  eval::RpeOptions tooFar = metres;
  tooFar.delta = 1e6;
  EXPECT_THROW(eval::computeRpe(d.gt, d.est, tooFar), orbis::Error);
}

// KITTI's devkit on a straight 1 m-per-frame drive: distances are exact integers, so every
// segment's frame span is known (the first frame strictly beyond the length: len + 1 steps).
std::vector<SE3d> straightDrive(std::size_t n, double stepLength) {
  std::vector<SE3d> poses;
  for (std::size_t i = 0; i < n; ++i)
    poses.emplace_back(SO3d(), Eigen::Vector3d(0, 0, stepLength * static_cast<double>(i)));
  return poses;
}

TEST(KittiMetric, DevkitSegmentsOnAStraightDrive) {
  const std::vector<SE3d> gt = straightDrive(1000, 1.0);
  const std::vector<double> dist = eval::trajectoryDistances(gt);
  EXPECT_EQ(dist[999], 999.0);
  EXPECT_EQ(eval::lastFrameFromSegmentLength(dist, 0, 100), 101);
  EXPECT_EQ(eval::lastFrameFromSegmentLength(dist, 900, 100), -1);  // frame 1000 does not exist
  // Segments: from every 10th frame f, each length L with f + L + 1 <= 999.
  std::size_t expectedSegments = 0;
  for (std::size_t f = 0; f < 1000; f += 10)
    for (int l = 100; l <= 800; l += 100) expectedSegments += f + static_cast<std::size_t>(l) + 1 <= 999;
  const eval::KittiResult perfect = eval::computeKittiMetric(gt, gt);
  EXPECT_EQ(perfect.segments.size(), expectedSegments);
  EXPECT_EQ(perfect.translationPercent, 0.0);
  EXPECT_LT(perfect.rotationDegPer100m, 1e-9);
  EXPECT_EQ(perfect.perLength.size(), 8u);
}

TEST(KittiMetric, ScaleDriftGivesItsPercentage) {
  // The estimate drives 1.02 m for every metre: 2 % translation error on every segment.
  const eval::KittiResult r = eval::computeKittiMetric(straightDrive(1000, 1.0), straightDrive(1000, 1.02));
  // Segment error = 0.02 * (L + 1) / L for L + 1 steps over a length L.
  double expected = 0;
  for (const auto& s : r.segments) expected += 0.02 * (s.length + 1) / s.length;
  expected *= 100.0 / static_cast<double>(r.segments.size());
  EXPECT_NEAR(r.translationPercent, expected, 1e-9);
  EXPECT_NEAR(r.translationPercent, 2.0, 0.05);
  EXPECT_LT(r.rotationDegPer100m, 1e-9);
  for (const auto& l : r.perLength) EXPECT_NEAR(l.translationPercent, 2.0 * (l.length + 1) / l.length, 1e-9);
}

TEST(KittiMetric, HeadingDriftGivesItsDegreesPer100m) {
  // A yaw drift of 0.001 rad per metre driven: 5.73 deg / 100 m, and (L+1) steps per segment.
  const double yawPerFrame = 0.001;
  const std::vector<SE3d> gt = straightDrive(900, 1.0);
  std::vector<SE3d> est{gt.front()};
  const SE3d drift(SO3d::exp(Eigen::Vector3d(0, yawPerFrame, 0)), Eigen::Vector3d::Zero());
  for (std::size_t i = 1; i < gt.size(); ++i)
    est.push_back(est.back() * (gt[i - 1].inverse() * gt[i]) * drift);
  const eval::KittiResult r = eval::computeKittiMetric(gt, est);
  for (const auto& s : r.segments)
    EXPECT_NEAR(s.rotationError, yawPerFrame * (s.length + 1) / s.length, 1e-9);
  EXPECT_NEAR(r.rotationDegPer100m, yawPerFrame * 180.0 / std::numbers::pi * 100.0, 0.02 * 5.73);
  EXPECT_GT(r.translationPercent, 1.0);  // the heading error bends the path away
}

TEST(KittiMetric, TooShortOrMismatchedIsAnError) {
  EXPECT_THROW(eval::computeKittiMetric(straightDrive(60, 1.0), straightDrive(60, 1.0)), orbis::Error);
  EXPECT_THROW(eval::computeKittiMetric(straightDrive(200, 1.0), straightDrive(199, 1.0)), orbis::Error);
}

}  // namespace
