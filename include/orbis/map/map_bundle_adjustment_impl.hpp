// orbis/map/map_bundle_adjustment_impl.hpp — bodies of map_bundle_adjustment.hpp.
//
// Contract: included by map_bundle_adjustment.hpp only; see there.
#pragma once

#include <map>
#include <mutex>
#include <set>
#include <vector>

#include "orbis/map/map_bundle_adjustment.hpp"
#include "orbis/optim/slam_ba.hpp"

namespace orbis {

namespace map_ba_detail {

// A BA problem copied out of the map as plain values (optim/slam_ba.hpp's input).
struct BaSnapshot {
  std::vector<KeyFrame*> keyFrames;  // pose index -> keyframe
  std::vector<SE3d> poses;
  std::vector<char> poseFixed;
  std::vector<MapPoint*> points;  // point index -> map point
  std::vector<Eigen::Vector3d> positions;
  std::vector<optim::SlamObservation> observations;  // keyframe keyFrames[pose] sees points[point]
  std::vector<std::size_t> keypointOf;               // per observation: the keyframe's keypoint
};

// Builds the problem for `free` keyframes and `points`; keyframes outside `free` that observe the
// points enter fixed. A map's root keyframe is always fixed (KeyFrame::isGauge). Keypoints deeper than
// depthLimit are monocular observations (bundleAdjustmentDepthLimit). Caller holds the map mutex.
inline void buildSnapshot(BaSnapshot& s, const std::vector<KeyFrame*>& free, const std::vector<MapPoint*>& points,
                          double depthLimit) {
  std::map<KeyFrame*, int, ById> poseOf;
  auto addPose = [&](KeyFrame* kf, bool fixed) {
    const int index = static_cast<int>(s.poses.size());
    s.keyFrames.push_back(kf);
    s.poses.push_back(kf->Tcw());
    s.poseFixed.push_back(fixed ? 1 : 0);
    return poseOf.emplace(kf, index).first;
  };
  for (KeyFrame* kf : free) addPose(kf, kf->isGauge());
  for (MapPoint* p : points) {
    const int pointIndex = static_cast<int>(s.positions.size());
    s.points.push_back(p);
    s.positions.push_back(p->position());
    for (const auto& [kf, index] : p->observations()) {
      if (kf->isBad()) continue;
      auto it = poseOf.find(kf);
      if (it == poseOf.end()) it = addPose(kf, true);
      const FrameFeatures& f = kf->features();
      const Keypoint& k = f.keypointsUn[index];
      const double uRight = f.depth[index] > depthLimit ? -1.0 : f.uRight[index];  // far: monocular
      s.observations.push_back({it->second, pointIndex, Eigen::Vector3d(k.u, k.v, uRight),
                                f.scales.invSigma2[static_cast<std::size_t>(k.octave)]});
      s.keypointOf.push_back(index);
    }
  }
}

// LocalBundleAdjustmentStats' disparity bias over the solved snapshot (features are immutable:
// no lock needed).
template <CameraModel Camera>
void disparityBias(const Camera& camera, const BaSnapshot& s, const std::vector<char>& outlier,
                   LocalBundleAdjustmentStats& stats) {
  double close = 0, far = 0;
  for (std::size_t k = 0; k < s.observations.size(); ++k) {
    if (outlier[k]) continue;
    const auto pose = static_cast<std::size_t>(s.observations[k].pose);
    const FrameFeatures& f = s.keyFrames[pose]->features();
    const std::size_t i = s.keypointOf[k];
    if (f.uRight[i] < 0) continue;
    const double z = (s.poses[pose] * s.positions[static_cast<std::size_t>(s.observations[k].point)]).z();
    if (z <= 0) continue;
    const double d = (f.keypointsUn[i].u - f.uRight[i]) - camera.bf() / z;
    if (f.depth[i] > camera.closeDepthThreshold()) { far += d; ++stats.farStereo; }
    else { close += d; ++stats.closeStereo; }
  }
  if (stats.closeStereo) stats.closeDisparityBias = close / stats.closeStereo;
  if (stats.farStereo) stats.farDisparityBias = far / stats.farStereo;
}

template <optim::RobustKernel Kernel, CameraModel Camera>
optim::BundleAdjustmentResult solve(const Camera& camera, BaSnapshot& s, const optim::BundleAdjustmentOptions& options) {
  return optim::bundleAdjustment<Kernel>(camera, s.poses, s.poseFixed, s.positions, s.observations, options);
}

}  // namespace map_ba_detail

template <optim::RobustKernel Kernel, CameraModel Camera>
LocalBundleAdjustmentStats localBundleAdjustment(const Camera& camera, Map& map, KeyFrame* kf,
                                                 std::atomic<bool>* abort, int threads) {
  using namespace map_ba_detail;
  LocalBundleAdjustmentStats stats;
  BaSnapshot s;
  {
    std::lock_guard lock(map.mutex());
    if (kf->isBad()) return stats;
    std::vector<KeyFrame*> local{kf};
    for (KeyFrame* n : kf->covisibles())
      if (!n->isBad()) local.push_back(n);
    const std::vector<MapPoint*> points = distinctGoodPoints(local);
    buildSnapshot(s, local, points, bundleAdjustmentDepthLimit(camera));
    stats.keyFrames = static_cast<int>(local.size());
    stats.fixedKeyFrames = static_cast<int>(s.keyFrames.size() - local.size());
    stats.points = static_cast<int>(points.size());
    stats.observations = static_cast<int>(s.observations.size());
  }
  if (s.observations.empty()) return stats;
  // ORB-SLAM's LocalBundleAdjustment: 5 robust iterations, then 10 without the outliers and
  // without the kernel.
  optim::BundleAdjustmentOptions options;
  options.iterations = 5;
  options.refineIterations = 10;
  options.abortFlag = abort;
  options.threads = threads;
  const optim::BundleAdjustmentResult result = solve<Kernel>(camera, s, options);
  stats.aborted = result.robustPass.termination == optim::Termination::Aborted ||
                  result.refinePass.termination == optim::Termination::Aborted;
  if constexpr (StereoCameraModel<Camera>) disparityBias(camera, s, result.outlier, stats);
  stats.iterations = result.robustPass.iterations + result.refinePass.iterations;

  std::lock_guard lock(map.mutex());
  for (std::size_t k = 0; k < s.observations.size(); ++k) {
    if (!result.outlier[k]) continue;
    KeyFrame* kf = s.keyFrames[static_cast<std::size_t>(s.observations[k].pose)];
    MapPoint* point = s.points[static_cast<std::size_t>(s.observations[k].point)];
    const std::size_t keypoint = s.keypointOf[k];
    if (point->isBad() || kf->isBad() || kf->point(keypoint) != point) continue;
    kf->erasePoint(keypoint);
    point->eraseObservation(kf);
    ++stats.outliersRemoved;
  }
  for (std::size_t i = 0; i < s.keyFrames.size(); ++i) {
    KeyFrame* k = s.keyFrames[i];
    if (!s.poseFixed[i] && !k->isBad()) k->setPose(s.poses[i]);
  }
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    MapPoint* p = s.points[i];
    if (p->isBad()) continue;
    p->setPosition(s.positions[i]);
    p->updateNormalAndDepth();
  }
  return stats;
}

template <optim::RobustKernel Kernel, CameraModel Camera>
FullBundleAdjustmentResult fullBundleAdjustment(const Camera& camera, Map& map, int iterations,
                                                std::atomic<bool>* abort, std::uint32_t mapId, int threads) {
  using namespace map_ba_detail;
  FullBundleAdjustmentResult result;
  BaSnapshot s;
  {
    std::lock_guard lock(map.mutex());
    const auto keyFrames = map.keyFrames(mapId);
    if (keyFrames.empty()) return result;
    buildSnapshot(s, keyFrames, map.mapPoints(mapId), bundleAdjustmentDepthLimit(camera));
  }
  // Huber throughout, no outlier pass: the loop closer merges the result through the spanning tree.
  optim::BundleAdjustmentOptions options;
  options.iterations = iterations;
  options.refineIterations = 0;
  options.abortFlag = abort;
  options.threads = threads;
  const optim::BundleAdjustmentResult solved = solve<Kernel>(camera, s, options);
  result.aborted = solved.robustPass.termination == optim::Termination::Aborted || (abort && abort->load());
  for (std::size_t i = 0; i < s.keyFrames.size(); ++i) result.keyFramePoses[s.keyFrames[i]->id] = s.poses[i];
  for (std::size_t i = 0; i < s.points.size(); ++i) result.pointPositions[s.points[i]->id] = s.positions[i];
  return result;
}

}  // namespace orbis
