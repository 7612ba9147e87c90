// orbis/mapping/local_mapper_impl.hpp — bodies of LocalMapper<Sensor> (local_mapper.hpp).
//
// Contract: included by local_mapper.hpp only; see there.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>

#include "orbis/map/map_bundle_adjustment.hpp"
#include "orbis/map/map_matching.hpp"
#include "orbis/mapping/local_mapper.hpp"

namespace orbis {

template <SensorConfiguration Sensor>
LocalMapper<Sensor>::LocalMapper(const Camera& camera, Map& map, LocalMapperOptions options, StageTimer* timer)
    : camera_(camera), map_(map), options_(options), timer_(timer) {
  if (options_.threaded) worker_.start([this] { serveQueue(); }, options_.backgroundPriority, "orbis-mapping");
}

template <SensorConfiguration Sensor>
LocalMapper<Sensor>::~LocalMapper() { shutdown(); }

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::shutdown() {
  worker_.stop();
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::insertKeyFrame(KeyFrame* kf) {
  abortBA_ = true;
  {
    std::lock_guard lock(triangulatedMutex_);
    ++queuedTotal_;
  }
  worker_.push(kf);
}

template <SensorConfiguration Sensor>
std::size_t LocalMapper<Sensor>::queuedKeyFrames() const {
  return worker_.size();
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::requestStop() {
  std::lock_guard lock(stopMutex_);
  stopRequested_ = true;
  abortBA_ = true;
  worker_.wake();
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::isStopped() const {
  std::lock_guard lock(stopMutex_);
  return stopped_;
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::isStoppedOrStopping() const {
  std::lock_guard lock(stopMutex_);
  return stopped_ || stopRequested_;
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::setNotStop(bool flag) {
  std::lock_guard lock(stopMutex_);
  if (flag && stopped_) return false;
  notStop_ = flag;
  return true;
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::release() {
  std::lock_guard lock(stopMutex_);
  stopped_ = false;
  stopRequested_ = false;
  worker_.wake();
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::stopIfRequested() {
  std::lock_guard lock(stopMutex_);
  if (stopRequested_ && !notStop_) {
    stopped_ = true;
    return true;
  }
  return false;
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::serveQueue() {
  if (isStopped()) {
    // Loop correction holds mapping stopped; with keyframes queued the worker's wait returns at
    // once, so wait here instead of spinning until release().
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return;
  }
  if (stopIfRequested()) return;
  acceptKeyFrames_ = false;
  while (!worker_.finishing() && !isStoppedOrStopping() && processOne()) {
  }
  acceptKeyFrames_ = true;
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::runUntilIdle() {
  acceptKeyFrames_ = false;
  while (processOne()) {
  }
  acceptKeyFrames_ = true;
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::waitUntilIdle() {
  worker_.waitUntilIdle([this] { runUntilIdle(); });
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::waitUntilIdleFor(std::chrono::steady_clock::duration budget) {
  return worker_.waitUntilIdleFor(budget);
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::waitUntilTriangulatedFor(std::chrono::steady_clock::duration budget) {
  std::unique_lock lock(triangulatedMutex_);
  const std::uint64_t target = queuedTotal_;
  return triangulatedCv_.wait_for(lock, budget, [&] { return triangulatedTotal_ >= target; });
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::waitUntilQueuedBelowFor(std::size_t count, std::chrono::steady_clock::duration budget) {
  return worker_.waitUntilFewerThanFor(count, budget);
}

template <SensorConfiguration Sensor>
bool LocalMapper<Sensor>::processOne() {
  const std::optional<KeyFrame*> next = worker_.pop();
  if (!next) return false;
  KeyFrame* kf = *next;
  ScopedStage total(timer_, "mapping: total");
  diagnostics_.clear();
  note("keyframe", static_cast<double>(kf->id));
  note("frame", static_cast<double>(kf->frameIndex));
  note("queued", static_cast<double>(queuedKeyFrames()));
  {
    // Tracking leaves a keyframe's bag of words to this thread; computed outside the map's lock
    // (the features are immutable), so tracking is not held up by it.
    ScopedStage stage(timer_, "mapping: bag of words");
    kf->ensureBow();
  }
  {
    ScopedStage stage(timer_, "mapping: keyframe insertion");
    std::lock_guard lock(map_.mutex());
    processNewKeyFrame(kf);
  }
  {
    ScopedStage stage(timer_, "mapping: map point culling");
    std::lock_guard lock(map_.mutex());
    cullRecentPoints(kf);
  }
  {
    ScopedStage stage(timer_, "mapping: map point creation");
    std::lock_guard lock(map_.mutex());
    createNewMapPoints(kf);
  }
  {
    std::lock_guard lock(triangulatedMutex_);
    ++triangulatedTotal_;
  }
  triangulatedCv_.notify_all();
  const bool moreQueued = queuedKeyFrames() > 0;
  if (!moreQueued) {
    {
      ScopedStage stage(timer_, "mapping: fusion");
      std::lock_guard lock(map_.mutex());
      fuseWithNeighbours(kf);
    }
    abortBA_ = false;
    if (!isStoppedOrStopping()) {
      {
        ScopedStage stage(timer_, "mapping: local BA");
        std::atomic<bool>* abort = options_.threaded ? &abortBA_ : nullptr;
        const LocalBundleAdjustmentStats ba = localBundleAdjustment<typename Sensor::RobustKernel>(camera_, map_, kf, abort);
        note("ba_keyframes", ba.keyFrames);
        note("ba_fixed", ba.fixedKeyFrames);
        note("ba_points", ba.points);
        note("ba_observations", ba.observations);
        note("ba_outliers_removed", ba.outliersRemoved);
        note("ba_aborted", ba.aborted);
        note("ba_iterations", ba.iterations);
        note("close_disparity_bias", ba.closeDisparityBias);
        note("far_disparity_bias", ba.farDisparityBias);
        note("far_stereo", ba.farStereo);
      }
      if (options_.cullKeyFrames) {
        ScopedStage stage(timer_, "mapping: keyframe culling");
        std::lock_guard lock(map_.mutex());
        cullKeyFrames(kf);
      }
    }
  }
  if (sink_) sink_(kf);
  if (timer_ && timer_->eventsEnabled()) {
    std::lock_guard lock(map_.mutex());
    note("skipped_ba", moreQueued);
    note("keyframe_points", kf->trackedPoints(0));
    note("map_points", static_cast<double>(map_.mapPointCount()));
    timer_->event("keyframe", std::move(diagnostics_));
    diagnostics_.clear();
  }
  return true;
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::processNewKeyFrame(KeyFrame* kf) {
  int fromTracking = 0;
  for (std::size_t i = 0; i < kf->size(); ++i) {
    MapPoint* p = kf->point(i);
    if (!p) continue;
    if (p->isBad()) {
      kf->erasePoint(i);
      continue;
    }
    if (!p->isObservedBy(kf)) {
      p->addObservation(kf, i);
      p->updateNormalAndDepth();
      p->computeDistinctiveDescriptor();
    } else if (p->reference() == kf) {
      recentPoints_.push_back(p);  // created by tracking from this keyframe's depth
      ++fromTracking;
    }
  }
  kf->updateConnections();
  note("points_from_tracking", fromTracking);
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::cullRecentPoints(KeyFrame* kf) {
  int culledRatio = 0, culledObservations = 0;
  const int minObservations = Sensor::kMetricScale ? 3 : 2;  // ORB-SLAM2: 2 for monocular
  for (auto it = recentPoints_.begin(); it != recentPoints_.end();) {
    MapPoint* p = *it;
    const KeyFrameId age = kf->id - p->firstKeyFrame;
    if (p->isBad()) {
      it = recentPoints_.erase(it);
    } else if (p->foundRatio() < 0.25f) {
      ++culledRatio;
      p->setBad();
      it = recentPoints_.erase(it);
    } else if (age >= 2 && p->observationCount() <= minObservations) {
      ++culledObservations;
      p->setBad();
      it = recentPoints_.erase(it);
    } else if (age >= 3) {
      it = recentPoints_.erase(it);  // mature: stays
    } else {
      ++it;
    }
  }
  note("culled_found_ratio", culledRatio);
  note("culled_observations", culledObservations);
}

namespace mapping_detail {

// Fundamental matrix mapping points of kf1 to epipolar lines of kf2 (x2ᵀ F x1 = 0).
template <CameraModel Camera>
Eigen::Matrix3d fundamental(const Camera& camera, const KeyFrame& kf1, const KeyFrame& kf2) {
  const SE3d T21 = kf2.Tcw() * kf1.Tcw().inverse();
  const Eigen::Matrix3d K = pinholeOf(camera).K();
  return fundamentalFromPose(T21.rotationMatrix(), T21.translation(), K, K);
}

// The triangulated point reprojects within χ² (95%) of keypoint i: 2 dof, 3 with a right coordinate;
// in the lens's pixels for a camera that observes through one.
template <CameraModel Camera>
bool reprojectionOk(const Camera& camera, const KeyFrame& kf, std::size_t i, const Eigen::Vector3d& pc) {
  const Keypoint& k = kf.features().keypointsUn[i];
  const double sigma2 = kf.features().scales.sigma2[static_cast<std::size_t>(k.octave)];
  if constexpr (ObservesThroughLens<Camera>) {
    const Eigen::Vector2d error = camera.lens.project(pc) - camera.lensPixel(Eigen::Vector2d(k.u, k.v));
    return error.squaredNorm() <= 5.991 * sigma2;
  }
  const Eigen::Vector3d obs = matching::detail::projectWithRight(camera, pc);
  const double ex = obs.x() - k.u, ey = obs.y() - k.v;
  const float uR = kf.features().uRight[i];
  if (uR < 0) return ex * ex + ey * ey <= 5.991 * sigma2;
  const double er = obs.z() - uR;
  return ex * ex + ey * ey + er * er <= 7.8 * sigma2;
}

// The median depth of the keyframe's map points in its camera (ORB-SLAM's
// ComputeSceneMedianDepth); 0 without points.
inline double sceneMedianDepth(const KeyFrame& kf) {
  const SE3d Tcw = kf.Tcw();
  std::vector<double> depths;
  kf.forEachPoint([&](const MapPoint* p) {
    if (!p->isBad()) depths.push_back((Tcw * p->position()).z());
  });
  if (depths.empty()) return 0;
  const auto middle = depths.begin() + static_cast<std::ptrdiff_t>((depths.size() - 1) / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return *middle;
}

// Monocular maps grow only by triangulation, so ORB-SLAM2 searches twice as many neighbours.
template <class Sensor>
std::size_t neighbourCount(int stereoCount) {
  return static_cast<std::size_t>(Sensor::kMetricScale ? stereoCount : 2 * stereoCount);
}

// A monocular pair whose baseline is under 1% of the scene depth cannot triangulate reliably.
inline constexpr double kMinBaselineToDepth = 0.01;

}  // namespace mapping_detail

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::createNewMapPoints(KeyFrame* kf) {
  const auto neighbours = kf->bestCovisibles(mapping_detail::neighbourCount<Sensor>(options_.triangulationNeighbours));
  const FrameFeatures& f1 = kf->features();
  const Eigen::Vector3d c1 = kf->cameraCenter();
  const SE3d Tcw1 = kf->Tcw();
  const double ratioFactor = 1.5 * f1.scales.factor();
  const PinholeCamera<double>& pinhole = pinholeOf(camera_);
  int created = 0;
  double baseline = 0;  // a pair needs a wider base than the stereo one to beat its depth
  if constexpr (StereoCameraModel<Camera>) baseline = camera_.bf() / pinhole.fx;
  for (KeyFrame* kf2 : neighbours) {
    if (queuedKeyFrames() > 0 && kf2 != neighbours.front()) break;  // ORB-SLAM: yield to new keyframes
    const Eigen::Vector3d c2 = kf2->cameraCenter();
    if constexpr (Sensor::kMetricScale) {
      if ((c2 - c1).norm() < baseline) continue;  // stereo depth is better than this baseline
    } else {
      const double medianDepth = mapping_detail::sceneMedianDepth(*kf2);
      if (!(medianDepth > 0) || (c2 - c1).norm() / medianDepth < mapping_detail::kMinBaselineToDepth) continue;
    }
    const auto pairs =
        matching::matchForTriangulation(camera_, *kf, *kf2, mapping_detail::fundamental(camera_, *kf, *kf2), false);
    const FrameFeatures& f2 = kf2->features();
    const SE3d Tcw2 = kf2->Tcw();
    const Eigen::Matrix3d Rwc1 = Tcw1.inverse().rotationMatrix(), Rwc2 = Tcw2.inverse().rotationMatrix();
    for (const auto& [i, j] : pairs) {
      const Keypoint& k1 = f1.keypointsUn[i];
      const Keypoint& k2 = f2.keypointsUn[j];
      const bool stereo1 = f1.uRight[i] >= 0, stereo2 = f2.uRight[j] >= 0;
      const Eigen::Vector3d xn1 = pinhole.normalizedRay(Eigen::Vector2d(k1.u, k1.v));
      const Eigen::Vector3d xn2 = pinhole.normalizedRay(Eigen::Vector2d(k2.u, k2.v));
      const Eigen::Vector3d ray1 = Rwc1 * xn1, ray2 = Rwc2 * xn2;
      const double cosRays = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
      const double cosStereo1 = stereo1 ? std::cos(2 * std::atan2(baseline / 2, f1.depth[i])) : 2.0;
      const double cosStereo2 = stereo2 ? std::cos(2 * std::atan2(baseline / 2, f2.depth[j])) : 2.0;
      const double cosStereo = std::min(cosStereo1, cosStereo2);
      Eigen::Vector3d x3d;
      if (cosRays < cosStereo && cosRays > 0 && (stereo1 || stereo2 || cosRays < 0.9998)) {
        // Linear triangulation (DLT) from the two views.
        const Eigen::Matrix<double, 3, 4> P1 = Tcw1.matrix3x4(), P2 = Tcw2.matrix3x4();
        Eigen::Matrix4d A;
        A.row(0) = xn1.x() * P1.row(2) - P1.row(0);
        A.row(1) = xn1.y() * P1.row(2) - P1.row(1);
        A.row(2) = xn2.x() * P2.row(2) - P2.row(0);
        A.row(3) = xn2.y() * P2.row(2) - P2.row(1);
        const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
        const Eigen::Vector4d h = svd.matrixV().col(3);
        if (std::abs(h(3)) < 1e-12) continue;
        x3d = h.head<3>() / h(3);
      } else if (stereo1 && cosStereo1 < cosStereo2) {
        if (!pointFromDepth(camera_, f1, i, Tcw1, x3d)) continue;
      } else if (stereo2 && cosStereo2 < cosStereo1) {
        if (!pointFromDepth(camera_, f2, j, Tcw2, x3d)) continue;
      } else {
        continue;  // too little parallax
      }
      const Eigen::Vector3d pc1 = Tcw1 * x3d, pc2 = Tcw2 * x3d;
      if (pc1.z() <= 0 || pc2.z() <= 0) continue;
      if (!mapping_detail::reprojectionOk(camera_, *kf, i, pc1) || !mapping_detail::reprojectionOk(camera_, *kf2, j, pc2))
        continue;
      // Scale consistency: distance ratio must agree with the pyramid levels' ratio.
      const double dist1 = (x3d - c1).norm(), dist2 = (x3d - c2).norm();
      if (dist1 == 0 || dist2 == 0) continue;
      const double ratioDist = dist2 / dist1;
      const double ratioOctave = f1.scales.scale[static_cast<std::size_t>(k1.octave)] /
                                 f2.scales.scale[static_cast<std::size_t>(k2.octave)];
      if (ratioDist * ratioFactor < ratioOctave || ratioDist > ratioOctave * ratioFactor) continue;
      MapPoint* p = map_.createMapPoint(x3d, kf, kf->frameIndex);
      p->addObservation(kf, i);
      p->addObservation(kf2, j);
      kf->setPoint(i, p);
      kf2->setPoint(j, p);
      p->computeDistinctiveDescriptor();
      p->updateNormalAndDepth();
      recentPoints_.push_back(p);
      ++created;
    }
  }
  note("triangulated", created);
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::fuseWithNeighbours(KeyFrame* kf) {
  std::vector<KeyFrame*> targets;
  std::set<KeyFrame*, ById> seen{kf};
  for (KeyFrame* n : kf->bestCovisibles(mapping_detail::neighbourCount<Sensor>(10))) {
    if (n->isBad() || !seen.insert(n).second) continue;
    targets.push_back(n);
    for (KeyFrame* n2 : n->bestCovisibles(5))
      if (!n2->isBad() && seen.insert(n2).second) targets.push_back(n2);
  }
  const std::vector<MapPoint*> own = kf->goodPoints();
  int fused = 0;
  for (KeyFrame* t : targets) fused += matching::fuse(camera_, *t, own);
  fused += matching::fuse(camera_, *kf, distinctGoodPoints(targets));
  note("fused", fused);
  for (MapPoint* p : kf->goodPoints()) {
    p->computeDistinctiveDescriptor();
    p->updateNormalAndDepth();
  }
  kf->updateConnections();
}

template <SensorConfiguration Sensor>
void LocalMapper<Sensor>::cullKeyFrames(KeyFrame* kf) {
  const std::vector<KeyFrame*> neighbours = kf->covisibles();
  for (KeyFrame* k : neighbours) {
    if (k->isMapRoot() || k->isBad() || k->isProtected()) continue;
    const FrameFeatures& f = k->features();
    int points = 0, redundant = 0;
    for (std::size_t i = 0; i < k->size(); ++i) {
      MapPoint* p = k->point(i);
      if (!p || p->isBad()) continue;
      // Stereo/RGB-D keyframes judge redundancy on their close points only (ORB-SLAM2).
      if constexpr (Sensor::kMetricScale) {
        if (f.depth[i] <= 0 || f.depth[i] > camera_.closeDepthThreshold()) continue;
      }
      ++points;
      if (p->observationCount() <= 3) continue;
      const int octave = f.keypointsUn[i].octave;
      int seenElsewhere = 0;
      for (const auto& [other, j] : p->observations()) {
        if (other == k) continue;
        if (other->features().keypointsUn[j].octave <= octave + 1 && ++seenElsewhere >= 3) break;
      }
      if (seenElsewhere >= 3) ++redundant;
    }
    if (points > 0 && redundant > options_.redundancyRatio * points) {
      note("culled_keyframe", static_cast<double>(k->id));
      k->setBad();
      if (culledSink_) culledSink_(k);
    }
  }
}

}  // namespace orbis
