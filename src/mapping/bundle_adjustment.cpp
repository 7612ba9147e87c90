#include "orbis/mapping/bundle_adjustment.hpp"

#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "orbis/optim/slam_residuals.hpp"

namespace orbis {

namespace {

using optim::ResidualId;
using optim::SlamProblem;

struct Observation {
  KeyFrame* kf;
  MapPoint* point;
  std::size_t keypoint;
  ResidualId id;
  int pose, pointIndex;
  bool threeDof;  // stereo or depth residual: the 3-DOF χ² test
};

// A BA problem copied out of the map: the keyframes (free or fixed), points and observations.
struct BaSnapshot {
  std::unique_ptr<optim::ObservationCameras> cameras;
  SlamProblem problem;
  std::vector<KeyFrame*> keyFrames;  // problem pose index -> keyframe
  std::vector<MapPoint*> points;     // problem point index -> map point
  std::vector<Observation> observations;
};

// Builds the problem for `free` keyframes and `points`; keyframes outside `free` that observe the
// points enter fixed. The origin keyframe is always fixed (gauge). Caller holds the map mutex.
void buildSnapshot(BaSnapshot& s, const std::vector<KeyFrame*>& free, const std::vector<MapPoint*>& points) {
  const MapIntrinsics& K = free.front()->intrinsics;
  s.cameras = std::make_unique<optim::ObservationCameras>(K.fx, K.fy, K.cx, K.cy, K.bf, K.disparitySigma);
  std::map<KeyFrame*, int, ById> poseOf;
  for (KeyFrame* kf : free) {
    poseOf[kf] = s.problem.addPose(kf->Tcw(), kf->id == 0);
    s.keyFrames.push_back(kf);
  }
  for (MapPoint* p : points) {
    const int pi = s.problem.addPoint(p->position());
    s.points.push_back(p);
    for (const auto& [kf, index] : p->observations()) {
      if (kf->isBad()) continue;
      auto it = poseOf.find(kf);
      if (it == poseOf.end()) {
        it = poseOf.emplace(kf, s.problem.addPose(kf->Tcw(), true)).first;
        s.keyFrames.push_back(kf);
      }
      const FrameFeatures& f = kf->features();
      const Keypoint& k = f.keypointsUn[index];
      const double information = f.scales.invSigma2[static_cast<std::size_t>(k.octave)];
      Observation o{kf, p, index, {}, it->second, pi, false};
      o.id = s.cameras->add(s.problem, it->second, pi, k.u, k.v, f.uRight[index], information, o.threeDof);
      s.observations.push_back(o);
    }
  }
}

bool isOutlier(const BaSnapshot& s, const Observation& o) {
  const double chi2 = s.problem.chi2(o.id);
  if (chi2 > (o.threeDof ? optim::kChi2Stereo : optim::kChi2Mono)) return true;
  return (s.problem.pose(o.pose) * s.problem.point(o.pointIndex)).z() <= 0;
}

}  // namespace

LocalBundleAdjustmentStats localBundleAdjustment(Map& map, KeyFrame* kf, std::atomic<bool>* abort) {
  LocalBundleAdjustmentStats stats;
  BaSnapshot s;
  {
    std::lock_guard lock(map.mutex());
    if (kf->isBad()) return stats;
    std::vector<KeyFrame*> local{kf};
    for (KeyFrame* n : kf->covisibles())
      if (!n->isBad()) local.push_back(n);
    std::set<MapPoint*, ById> seen;
    std::vector<MapPoint*> points;
    for (KeyFrame* k : local)
      for (MapPoint* p : k->points())
        if (p && !p->isBad() && seen.insert(p).second) points.push_back(p);
    buildSnapshot(s, local, points);
    stats.keyFrames = static_cast<int>(local.size());
    stats.fixedKeyFrames = static_cast<int>(s.keyFrames.size() - local.size());
    stats.points = static_cast<int>(points.size());
    stats.observations = static_cast<int>(s.observations.size());
  }
  if (s.observations.empty()) return stats;
  optim::SolverOptions options;
  options.maxIterations = 5;
  options.abortFlag = abort;
  s.problem.solve(options);
  if (abort && abort->load()) {
    stats.aborted = true;
  } else {
    // Second pass without the outliers and without the kernel (ORB-SLAM's LocalBundleAdjustment).
    for (const Observation& o : s.observations) {
      if (isOutlier(s, o)) s.problem.setActive(o.id, false);
      s.problem.setKernelThreshold(o.id, std::numeric_limits<double>::infinity());
    }
    options.maxIterations = 10;
    s.problem.solve(options);
  }
  std::lock_guard lock(map.mutex());
  for (const Observation& o : s.observations) {
    if (!isOutlier(s, o)) continue;
    if (o.point->isBad() || o.kf->isBad() || o.kf->point(o.keypoint) != o.point) continue;
    o.kf->erasePoint(o.keypoint);
    o.point->eraseObservation(o.kf);
    ++stats.outliersRemoved;
  }
  for (std::size_t i = 0; i < s.keyFrames.size(); ++i) {
    KeyFrame* k = s.keyFrames[i];
    if (!s.problem.poseFixed(static_cast<int>(i)) && !k->isBad()) k->setPose(s.problem.pose(static_cast<int>(i)));
  }
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    MapPoint* p = s.points[i];
    if (p->isBad()) continue;
    p->setPosition(s.problem.point(static_cast<int>(i)));
    p->updateNormalAndDepth();
  }
  return stats;
}

FullBundleAdjustmentResult fullBundleAdjustment(Map& map, int iterations, std::atomic<bool>* abort) {
  FullBundleAdjustmentResult result;
  BaSnapshot s;
  {
    std::lock_guard lock(map.mutex());
    const auto keyFrames = map.keyFrames();
    if (keyFrames.empty()) return result;
    buildSnapshot(s, keyFrames, map.mapPoints());
  }
  optim::SolverOptions options;
  options.maxIterations = iterations;
  options.abortFlag = abort;
  s.problem.solve(options);
  result.aborted = abort && abort->load();
  for (std::size_t i = 0; i < s.keyFrames.size(); ++i) result.keyFramePoses[s.keyFrames[i]->id] = s.problem.pose(static_cast<int>(i));
  for (std::size_t i = 0; i < s.points.size(); ++i) result.pointPositions[s.points[i]->id] = s.problem.point(static_cast<int>(i));
  return result;
}

}  // namespace orbis
