// orbis/tracking/monocular_initialisation_impl.hpp — the monocular path of Tracker<Sensor>
// (ORB-SLAM's MonocularInitialization, T-RO 2015 §IV), for sensors without metric scale.
//
// Contract: included by tracker.hpp only. A frame with more than minInitialisationKeypoints
// keypoints becomes the reference; each later frame is matched to it in a window around where
// each reference keypoint was last matched (searchForInitialization: finest level, ratio 0.9,
// rotation histogram). Fewer than minInitialisationMatches matches drop the reference (the
// next frame starts again); otherwise the two-view initialiser runs, and a refusal keeps the
// reference for the next frame. An accepted pair becomes two keyframes (the reference at the
// origin) and a point per well-triangulated match, refined by BA over both views (20
// iterations under the sensor's kernel, the first pose fixed), then scaled so the points'
// median depth in the first keyframe is 1. The caller holds the map mutex.
#pragma once

#include <algorithm>

#include "orbis/features/matcher.hpp"
#include "orbis/optim/slam_ba.hpp"
#include "orbis/tracking/tracker.hpp"

namespace orbis {

namespace tracking_detail {

// ORB-SLAM's: the reprojected map must keep this many points to count as initialised.
inline constexpr std::size_t kMinInitialMapPoints = 100;
inline constexpr int kInitialBundleAdjustmentIterations = 20;
inline constexpr float kInitialisationMatchRatio = 0.9f;

inline optim::SlamObservation monocularObservation(const FrameFeatures& f, std::size_t i, int pose, int point) {
  const Keypoint& k = f.keypointsUn[i];
  return {pose, point, Eigen::Vector3d(k.u, k.v, -1.0), f.scales.invSigma2[static_cast<std::size_t>(k.octave)]};
}

// The median depth of points in a camera at the origin; 0 for none.
inline double medianDepth(const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> depths;
  depths.reserve(points.size());
  for (const auto& p : points) depths.push_back(p.z());
  if (depths.empty()) return 0;
  const auto middle = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return *middle;
}

// The two views after BA: the second camera's pose and the points (first camera = world), with
// the keypoint pair of each; points BA flagged in either view are left out.
struct InitialPair {
  SE3d secondPose;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::pair<std::size_t, std::size_t>> matches;
};

template <optim::RobustKernel Kernel, CameraModel Camera>
InitialPair refineInitialPair(const Camera& camera, const FrameFeatures& first, const FrameFeatures& second,
                              const std::vector<std::pair<std::size_t, std::size_t>>& pairs,
                              const TwoViewResult& twoView) {
  std::vector<SE3d> poses{SE3d(), SE3d(twoView.rotation, twoView.translation)};
  InitialPair triangulated;
  std::vector<optim::SlamObservation> observations;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!twoView.triangulated[k]) continue;
    const int point = static_cast<int>(triangulated.points.size());
    triangulated.points.push_back(twoView.points[k]);
    triangulated.matches.push_back(pairs[k]);
    observations.push_back(monocularObservation(first, pairs[k].first, 0, point));
    observations.push_back(monocularObservation(second, pairs[k].second, 1, point));
  }
  optim::BundleAdjustmentOptions ba;
  ba.iterations = kInitialBundleAdjustmentIterations;
  ba.refineIterations = 0;  // ORB-SLAM's initial BA: one robust pass
  const auto solved = optim::bundleAdjustment<Kernel>(camera, poses, {1, 0}, triangulated.points, observations, ba);
  InitialPair kept;
  kept.secondPose = poses[1];
  for (std::size_t l = 0; l < triangulated.points.size(); ++l) {
    if (solved.outlier[2 * l] || solved.outlier[2 * l + 1]) continue;
    kept.points.push_back(triangulated.points[l]);
    kept.matches.push_back(triangulated.matches[l]);
  }
  return kept;
}

}  // namespace tracking_detail

template <SensorConfiguration Sensor>
bool Tracker<Sensor>::initialiseFromTwoViews(FrameT& f)
  requires(!Sensor::kMetricScale)
{
  const auto minKeypoints = static_cast<std::size_t>(options_.minInitialisationKeypoints);
  if (!initialReference_ || f.size() <= minKeypoints) {
    initialReference_.reset();
    ++initialisationWaits_[f.size() > minKeypoints ? "new reference frame" : "too few keypoints"];
    if (f.size() > minKeypoints) {
      initialReference_ = f;
      initialPredicted_.clear();
      for (const Keypoint& k : f.features->keypointsUn) initialPredicted_.emplace_back(k.u, k.v);
    }
    return false;
  }
  const FrameFeatures& reference = *initialReference_->features;
  std::vector<int> matches12;
  const int matched = searchForInitialization(reference, *f.features, initialPredicted_,
                                                        options_.initialisationWindow,
                                                        tracking_detail::kInitialisationMatchRatio, true, matches12);
  note("initialisation_reference", static_cast<double>(initialReference_->index));
  note("initialisation_matches", matched);
  if (matched < options_.minInitialisationMatches) {
    initialisationRefusal_ = TwoViewRefusal::TooFewMatches;
    ++initialisationWaits_[std::string(toString(initialisationRefusal_))];
    initialReference_.reset();
    return false;
  }
  std::vector<TwoViewMatch> matches;
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i1 = 0; i1 < matches12.size(); ++i1) {
    if (matches12[i1] < 0) continue;
    const auto i2 = static_cast<std::size_t>(matches12[i1]);
    const Keypoint& k1 = reference.keypointsUn[i1];
    const Keypoint& k2 = f.features->keypointsUn[i2];
    initialPredicted_[i1] = {k2.u, k2.v};  // the next window opens where it was seen last
    matches.push_back({{k1.u, k1.v}, {k2.u, k2.v}, reference.scales.sigma2[std::size_t(k1.octave)],
                       f.features->scales.sigma2[std::size_t(k2.octave)]});
    pairs.emplace_back(i1, i2);
  }
  const TwoViewResult twoView = initialiseTwoView(matches, pinholeOf(*f.camera).K(), initialisationRng_);
  initialisationRefusal_ = twoView.refusal;
  note("initialisation_inliers", twoView.inliers);
  note("initialisation_good", twoView.goodPoints);
  note("initialisation_second_good", twoView.secondBestGood);
  note("initialisation_parallax_deg", twoView.parallaxDeg);
  note("initialisation_homography_ratio", twoView.homographyRatio);
  note("initialisation_homography", twoView.model == TwoViewModel::Homography);
  if (!twoView.accepted()) {
    ++initialisationWaits_[std::string(toString(initialisationRefusal_))];
    return false;
  }
  return createInitialMap(f, pairs, twoView);
}

template <SensorConfiguration Sensor>
bool Tracker<Sensor>::createInitialMap(FrameT& f, const std::vector<std::pair<std::size_t, std::size_t>>& pairs,
                                       const TwoViewResult& twoView)
  requires(!Sensor::kMetricScale)
{
  FrameT& first = *initialReference_;
  const tracking_detail::InitialPair pair = tracking_detail::refineInitialPair<typename Sensor::RobustKernel>(
      *f.camera, *first.features, *f.features, pairs, twoView);
  const double median = tracking_detail::medianDepth(pair.points);
  if (!(median > 0) || pair.points.size() < tracking_detail::kMinInitialMapPoints) {
    initialisationRefusal_ = TwoViewRefusal::TooFewTriangulated;  // ORB-SLAM: "wrong initialization"
    ++initialisationWaits_[std::string(toString(initialisationRefusal_))];
    initialReference_.reset();
    return false;
  }
  // The map's unit: the median scene depth seen from the first keyframe.
  const double scale = 1.0 / median;
  first.Tcw = SE3d();
  f.Tcw = SE3d(pair.secondPose.so3(), pair.secondPose.translation() * scale);
  KeyFrame* kf1 = createKeyFrameFrom(first);
  KeyFrame* kf2 = createKeyFrameFrom(f);
  for (std::size_t l = 0; l < pair.points.size(); ++l) {
    const auto [i1, i2] = pair.matches[l];
    MapPoint* p = map_.createMapPoint(pair.points[l] * scale, kf2, f.index);
    p->addObservation(kf1, i1);
    p->addObservation(kf2, i2);
    kf1->setPoint(i1, p);
    kf2->setPoint(i2, p);
    p->computeDistinctiveDescriptor();
    p->updateNormalAndDepth();
    f.points[i2] = p;
    f.outlier[i2] = 0;
  }
  startMap(kf1, kf2, f);
  return true;
}

template <SensorConfiguration Sensor>
void Tracker<Sensor>::startMap(KeyFrame* first, KeyFrame* second, FrameT& f)
  requires(!Sensor::kMetricScale)
{
  first->updateConnections();
  second->updateConnections();
  // The reference frame is tracked too: it is the first keyframe, at the origin.
  tracked_.push_back({first->frameIndex, first->timestamp, first, SE3d(), first->mapId()});
  reference_ = second;
  lastKeyFrameFrame_ = f.index;
  localKeyFrames_ = {second, first};
  localPoints_ = map_.mapPoints(map_.activeMapId());
  matchesInliers_ = static_cast<int>(localPoints_.size());
  initialReference_.reset();
  if (mapper_) {
    mapper_->insertKeyFrame(first);
    mapper_->insertKeyFrame(second);
  }
}

}  // namespace orbis
