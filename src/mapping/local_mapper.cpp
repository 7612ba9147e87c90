#include "orbis/mapping/local_mapper.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/SVD>

#include "orbis/mapping/bundle_adjustment.hpp"
#include "orbis/tracking/map_matching.hpp"

namespace orbis {

LocalMapper::LocalMapper(Map& map, LocalMapperOptions options, StageTimer* timer)
    : map_(map), options_(options), timer_(timer) {
  if (options_.threaded) worker_ = std::thread([this] { run(); });
}

LocalMapper::~LocalMapper() { shutdown(); }

void LocalMapper::shutdown() {
  finish_ = true;
  queueCv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void LocalMapper::insertKeyFrame(KeyFrame* kf) {
  {
    std::lock_guard lock(queueMutex_);
    queue_.push_back(kf);
  }
  abortBA_ = true;
  queueCv_.notify_all();
}

std::size_t LocalMapper::queuedKeyFrames() const {
  std::lock_guard lock(queueMutex_);
  return queue_.size();
}

void LocalMapper::requestStop() {
  std::lock_guard lock(stopMutex_);
  stopRequested_ = true;
  abortBA_ = true;
  queueCv_.notify_all();
}

bool LocalMapper::isStopped() const {
  std::lock_guard lock(stopMutex_);
  return stopped_;
}

bool LocalMapper::isStoppedOrStopping() const {
  std::lock_guard lock(stopMutex_);
  return stopped_ || stopRequested_;
}

bool LocalMapper::setNotStop(bool flag) {
  std::lock_guard lock(stopMutex_);
  if (flag && stopped_) return false;
  notStop_ = flag;
  return true;
}

void LocalMapper::release() {
  std::lock_guard lock(stopMutex_);
  stopped_ = false;
  stopRequested_ = false;
  queueCv_.notify_all();
}

bool LocalMapper::stopIfRequested() {
  std::lock_guard lock(stopMutex_);
  if (stopRequested_ && !notStop_) {
    stopped_ = true;
    return true;
  }
  return false;
}

void LocalMapper::run() {
  while (!finish_) {
    {
      std::unique_lock lock(queueMutex_);
      queueCv_.wait_for(lock, std::chrono::milliseconds(5), [this] { return finish_ || !queue_.empty(); });
    }
    if (finish_) break;
    if (isStopped()) {
      // Loop correction holds mapping stopped; with keyframes queued the wait above returns at
      // once, so wait here instead of spinning until release().
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    if (stopIfRequested()) continue;
    acceptKeyFrames_ = false;
    busy_ = true;
    while (!finish_ && !isStoppedOrStopping() && processOne()) {
    }
    busy_ = false;
    acceptKeyFrames_ = true;
  }
}

void LocalMapper::runUntilIdle() {
  acceptKeyFrames_ = false;
  while (processOne()) {
  }
  acceptKeyFrames_ = true;
}

void LocalMapper::waitUntilIdle() {
  while (true) {
    if (queuedKeyFrames() == 0 && !busy_) return;
    if (!worker_.joinable()) {
      runUntilIdle();
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

bool LocalMapper::processOne() {
  KeyFrame* kf = nullptr;
  {
    std::lock_guard lock(queueMutex_);
    if (queue_.empty()) return false;
    kf = queue_.front();
    queue_.pop_front();
  }
  ScopedStage total(timer_, "mapping: total");
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
        localBundleAdjustment(map_, kf, abort);
      }
      if (options_.cullKeyFrames) {
        ScopedStage stage(timer_, "mapping: keyframe culling");
        std::lock_guard lock(map_.mutex());
        cullKeyFrames(kf);
      }
    }
  }
  if (sink_) sink_(kf);
  return true;
}

void LocalMapper::processNewKeyFrame(KeyFrame* kf) {
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
    }
  }
  kf->updateConnections();
}

void LocalMapper::cullRecentPoints(KeyFrame* kf) {
  const int minObservations = kf->intrinsics.bf > 0 ? 3 : 2;
  for (auto it = recentPoints_.begin(); it != recentPoints_.end();) {
    MapPoint* p = *it;
    const KeyFrameId age = kf->id - p->firstKeyFrame;
    if (p->isBad()) {
      it = recentPoints_.erase(it);
    } else if (p->foundRatio() < 0.25f) {
      p->setBad();
      it = recentPoints_.erase(it);
    } else if (age >= 2 && p->observationCount() <= minObservations) {
      p->setBad();
      it = recentPoints_.erase(it);
    } else if (age >= 3) {
      it = recentPoints_.erase(it);  // mature: stays
    } else {
      ++it;
    }
  }
}

namespace {

// Fundamental matrix mapping points of kf1 to epipolar lines of kf2 (x2ᵀ F x1 = 0).
Eigen::Matrix3d fundamental(const KeyFrame& kf1, const KeyFrame& kf2) {
  const SE3d T21 = kf2.Tcw() * kf1.Tcw().inverse();
  const auto K = [](const MapIntrinsics& k) {
    Eigen::Matrix3d m;
    m << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1;
    return m;
  };
  return fundamentalFromPose(T21.rotationMatrix(), T21.translation(), K(kf1.intrinsics), K(kf2.intrinsics));
}

bool reprojectionOk(const KeyFrame& kf, std::size_t i, const Eigen::Vector3d& pc) {
  const Keypoint& k = kf.features().keypointsUn[i];
  const double sigma2 = kf.features().scales.sigma2[static_cast<std::size_t>(k.octave)];
  const double invZ = 1.0 / pc.z();
  const double u = kf.intrinsics.fx * pc.x() * invZ + kf.intrinsics.cx;
  const double v = kf.intrinsics.fy * pc.y() * invZ + kf.intrinsics.cy;
  const double ex = u - k.u, ey = v - k.v;
  const float uR = kf.features().uRight[i];
  if (uR < 0) return ex * ex + ey * ey <= 5.991 * sigma2;
  const double er = u - kf.intrinsics.bf * invZ - uR;
  return ex * ex + ey * ey + er * er <= 7.8 * sigma2;
}

}  // namespace

void LocalMapper::createNewMapPoints(KeyFrame* kf) {
  const auto neighbours = kf->bestCovisibles(static_cast<std::size_t>(options_.triangulationNeighbours));
  const FrameFeatures& f1 = kf->features();
  const Eigen::Vector3d c1 = kf->cameraCenter();
  const SE3d Tcw1 = kf->Tcw();
  const double ratioFactor = 1.5 * f1.scales.factor();
  const double baseline1 = kf->intrinsics.bf / kf->intrinsics.fx;
  for (KeyFrame* kf2 : neighbours) {
    if (queuedKeyFrames() > 0 && kf2 != neighbours.front()) break;  // ORB-SLAM: yield to new keyframes
    const Eigen::Vector3d c2 = kf2->cameraCenter();
    if ((c2 - c1).norm() < baseline1) continue;  // stereo depth is better than this baseline
    const auto pairs = matching::matchForTriangulation(*kf, *kf2, fundamental(*kf, *kf2), false);
    const FrameFeatures& f2 = kf2->features();
    const SE3d Tcw2 = kf2->Tcw();
    const Eigen::Matrix3d Rwc1 = Tcw1.inverse().rotationMatrix(), Rwc2 = Tcw2.inverse().rotationMatrix();
    for (const auto& [i, j] : pairs) {
      const Keypoint& k1 = f1.keypointsUn[i];
      const Keypoint& k2 = f2.keypointsUn[j];
      const bool stereo1 = f1.uRight[i] >= 0, stereo2 = f2.uRight[j] >= 0;
      const Eigen::Vector3d xn1((k1.u - kf->intrinsics.cx) / kf->intrinsics.fx, (k1.v - kf->intrinsics.cy) / kf->intrinsics.fy, 1);
      const Eigen::Vector3d xn2((k2.u - kf2->intrinsics.cx) / kf2->intrinsics.fx, (k2.v - kf2->intrinsics.cy) / kf2->intrinsics.fy, 1);
      const Eigen::Vector3d ray1 = Rwc1 * xn1, ray2 = Rwc2 * xn2;
      const double cosRays = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
      const double cosStereo1 = stereo1 ? std::cos(2 * std::atan2(baseline1 / 2, f1.depth[i])) : 2.0;
      const double cosStereo2 = stereo2 ? std::cos(2 * std::atan2(kf2->intrinsics.bf / kf2->intrinsics.fx / 2, f2.depth[j])) : 2.0;
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
        if (!kf->unprojectStereo(i, x3d)) continue;
      } else if (stereo2 && cosStereo2 < cosStereo1) {
        if (!kf2->unprojectStereo(j, x3d)) continue;
      } else {
        continue;  // too little parallax
      }
      const Eigen::Vector3d pc1 = Tcw1 * x3d, pc2 = Tcw2 * x3d;
      if (pc1.z() <= 0 || pc2.z() <= 0) continue;
      if (!reprojectionOk(*kf, i, pc1) || !reprojectionOk(*kf2, j, pc2)) continue;
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
    }
  }
}

void LocalMapper::fuseWithNeighbours(KeyFrame* kf) {
  std::vector<KeyFrame*> targets;
  std::set<KeyFrame*, ById> seen{kf};
  for (KeyFrame* n : kf->bestCovisibles(10)) {
    if (n->isBad() || !seen.insert(n).second) continue;
    targets.push_back(n);
    for (KeyFrame* n2 : n->bestCovisibles(5))
      if (!n2->isBad() && seen.insert(n2).second) targets.push_back(n2);
  }
  const std::vector<MapPoint*> own = kf->goodPoints();
  for (KeyFrame* t : targets) matching::fuse(*t, own);
  std::vector<MapPoint*> candidates;
  std::set<MapPoint*, ById> candidateSet;
  for (KeyFrame* t : targets)
    for (MapPoint* p : t->points())
      if (p && !p->isBad() && candidateSet.insert(p).second) candidates.push_back(p);
  matching::fuse(*kf, candidates);
  for (MapPoint* p : kf->goodPoints()) {
    p->computeDistinctiveDescriptor();
    p->updateNormalAndDepth();
  }
  kf->updateConnections();
}

void LocalMapper::cullKeyFrames(KeyFrame* kf) {
  const std::vector<KeyFrame*> neighbours = kf->covisibles();
  for (KeyFrame* k : neighbours) {
    if (k->id == 0 || k->isBad() || k->isProtected()) continue;
    const FrameFeatures& f = k->features();
    int points = 0, redundant = 0;
    for (std::size_t i = 0; i < k->size(); ++i) {
      MapPoint* p = k->point(i);
      if (!p || p->isBad()) continue;
      // Stereo/RGB-D keyframes judge redundancy on their close points only (ORB-SLAM2).
      if (k->intrinsics.bf > 0 && (f.depth[i] <= 0 || f.depth[i] > k->intrinsics.closeDepth)) continue;
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
      k->setBad();
      if (culledSink_) culledSink_(k);
    }
  }
}

}  // namespace orbis
