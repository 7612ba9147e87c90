// orbis/loop/loop_closer_impl.hpp — LoopCloser<Sensor>'s queue, detection and relative pose.
//
// Contract: included by loop_closer.hpp only; see there.
#pragma once

#include <algorithm>
#include <cstdio>

#include "orbis/loop/loop_closer.hpp"
#include "orbis/loop/relative_pose.hpp"
#include "orbis/loop/sim3_solver.hpp"
#include "orbis/map/keyframe_matching.hpp"
#include "orbis/map/map_covisibility.hpp"

namespace orbis {

template <SensorConfiguration Sensor>
LoopCloser<Sensor>::LoopCloser(const Camera& camera, Map& map, LocalMappingControl* mapper,
                               bow::KeyframeDatabase& database, LoopCloserOptions options, StageTimer* timer)
    : camera_(camera),
      map_(map),
      mapper_(mapper),
      database_(database),
      options_(std::move(options)),
      timer_(timer),
      rng_(options_.seed) {
  if (options_.threaded)
    worker_.start(
        [this] {
          while (!worker_.finishing() && processOne()) {
          }
        },
        options_.backgroundPriority, "orbis-loop");
}

template <SensorConfiguration Sensor>
LoopCloser<Sensor>::~LoopCloser() { shutdown(); }

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::shutdown() {
  worker_.stop();
  stopFullBundleAdjustment();
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::insertKeyFrame(KeyFrame* kf) {
  worker_.push(kf);
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::runUntilIdle() {
  while (processOne()) {
  }
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::waitUntilIdle() {
  worker_.waitUntilIdle([this] { runUntilIdle(); }, [this] { return !fullBaRunning_.load(); });
}

template <SensorConfiguration Sensor>
std::vector<LoopClosureEvent> LoopCloser<Sensor>::closures() const {
  std::lock_guard lock(eventsMutex_);
  return events_;
}

template <SensorConfiguration Sensor>
std::vector<MapMergeEvent> LoopCloser<Sensor>::merges() const {
  std::lock_guard lock(eventsMutex_);
  return merges_;
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::report(const std::string& line) const {
  if (options_.log) {
    options_.log(line);
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());  // stdout may carry a --json report
  }
}

template <SensorConfiguration Sensor>
bool LoopCloser<Sensor>::processOne() {
  const std::optional<KeyFrame*> next = worker_.pop();
  if (!next) return false;
  KeyFrame* kf = *next;
  LoopCandidate loop;
  bool found = false, merge = false;
  {
    ScopedStage stage(timer_, "loop: detection");
    std::lock_guard lock(map_.mutex());
    dropBadKeyFrames();
    if (kf->isBad()) return true;
    kf->setProtected(true);  // local mapping must not cull it while we look at it
    std::vector<KeyFrame*> mergeCandidates;
    const std::vector<KeyFrame*> candidates = detectConsistentCandidates(kf, mergeCandidates);
    database_.add(kf->id, kf->bowVector());
    indexed_.push_back(kf);
    // A loop first; a place of another map only when no loop closes with this keyframe.
    const std::vector<KeyFrame*>* lists[] = {&candidates, &mergeCandidates};
    for (const std::vector<KeyFrame*>* list : lists) {
      if (found || list->empty()) continue;
      for (KeyFrame* c : *list) c->setProtected(true);
      found = computeRelativePose(kf, *list, loop);
      merge = found && list == &mergeCandidates;
      for (KeyFrame* c : *list)
        if (c != loop.loopKeyFrame || !found) c->setProtected(false);
    }
    if (!found) kf->setProtected(false);
  }
  if (found && merge) {
    ScopedStage stage(timer_, "loop: map merge");
    mergeMaps(kf, loop);
  } else if (found) {
    ScopedStage stage(timer_, "loop: correction");
    correctLoop(kf, loop);
  }
  return true;
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::dropBadKeyFrames() {
  std::erase_if(indexed_, [this](KeyFrame* k) {
    if (!k->isBad()) return false;
    database_.erase(k->id);
    return true;
  });
}

template <SensorConfiguration Sensor>
std::vector<KeyFrame*> LoopCloser<Sensor>::detectConsistentCandidates(KeyFrame* kf,
                                                                      std::vector<KeyFrame*>& mergeCandidates) {
  // Too soon after a loop, or too small a map: nothing to close. A merge needs the keyframe's map
  // to be the active one (a keyframe queued before tracking moved to another map does not) and
  // a few keyframes, with another map in the atlas.
  const bool tooSoon = anyLoop_ && kf->id < lastLoopKeyFrame_ + static_cast<KeyFrameId>(options_.keyFramesAfterLoop);
  const std::size_t ownKeyFrames = map_.keyFrameCount(kf->mapId());
  const bool loopsPossible = !tooSoon && ownKeyFrames > static_cast<std::size_t>(options_.keyFramesAfterLoop);
  const bool mergesPossible = !tooSoon && options_.mergeMaps && kf->mapId() == map_.activeMapId() &&
                              ownKeyFrames >= static_cast<std::size_t>(options_.mergeMinKeyFrames) &&
                              map_.keyFrameCount() > ownKeyFrames;
  if (!loopsPossible) consistentGroups_.clear();
  if (!mergesPossible) mergeGroups_.clear();
  if (!loopsPossible && !mergesPossible) return {};
  const MapCovisibility graph(map_);
  std::vector<KeyFrame*> sameMap, otherMaps;
  for (const bow::PlaceCandidate& c : database_.detectLoopCandidates(kf->id, kf->bowVector(), graph)) {
    KeyFrame* k = map_.keyFrame(c.keyframe);
    if (!k || k->isBad()) continue;
    (k->mapId() == kf->mapId() ? sameMap : otherMaps).push_back(k);
  }
  if (mergesPossible) mergeCandidates = keepConsistent(otherMaps, mergeGroups_);
  if (!loopsPossible) return {};
  return keepConsistent(sameMap, consistentGroups_);
}

template <SensorConfiguration Sensor>
std::vector<KeyFrame*> LoopCloser<Sensor>::keepConsistent(const std::vector<KeyFrame*>& candidates,
                                                          std::vector<ConsistentGroup>& groups) {
  if (candidates.empty()) {
    groups.clear();
    return {};
  }
  // ORB-SLAM's consistency check: a candidate's group (itself and its covisible keyframes) must
  // share a keyframe with a group that was consistent for the previous keyframes.
  std::vector<ConsistentGroup> current;
  std::vector<char> groupContinued(groups.size(), 0);
  std::vector<KeyFrame*> enough;
  for (KeyFrame* candidate : candidates) {
    ConsistentGroup group;
    group.members.insert(candidate->id);
    for (KeyFrame* n : candidate->covisibles())
      if (!n->isBad()) group.members.insert(n->id);
    bool consistentWithSome = false, added = false;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto& previous = groups[g].members;
      const bool shares = std::any_of(group.members.begin(), group.members.end(),
                                      [&](KeyFrameId id) { return previous.count(id) != 0; });
      if (!shares) continue;
      consistentWithSome = true;
      const int consistency = groups[g].consistency + 1;
      if (!groupContinued[g]) {
        current.push_back({group.members, consistency});
        groupContinued[g] = 1;
      }
      if (consistency >= options_.consistencyThreshold && !added) {
        enough.push_back(candidate);
        added = true;
      }
    }
    if (!consistentWithSome) current.push_back({group.members, 0});
  }
  groups = std::move(current);
  return enough;
}

namespace loop_detail {

// A similarity's camera pose at the scale of the world it maps from: [R | t / s].
inline SE3d rigidPart(const Sim3d& Scw) { return SE3d(Scw.so3(), Scw.translation() / Scw.scale()); }

inline loop::PointPair makePair(const KeyFrame& kf1, std::size_t i1, const KeyFrame& kf2, std::size_t i2) {
  const Keypoint& k1 = kf1.features().keypointsUn[i1];
  const Keypoint& k2 = kf2.features().keypointsUn[i2];
  loop::PointPair p;
  p.p1 = kf1.Tcw() * kf1.point(i1)->position();
  p.p2 = kf2.Tcw() * kf2.point(i2)->position();
  p.obs1 = {k1.u, k1.v};
  p.obs2 = {k2.u, k2.v};
  p.information1 = kf1.features().scales.invSigma2[static_cast<std::size_t>(k1.octave)];
  p.information2 = kf2.features().scales.invSigma2[static_cast<std::size_t>(k2.octave)];
  return p;
}

// Point pairs from per-keypoint matches (kf1 keypoint i -> kf2 map point), with kf1's indices.
inline void pairsFromMatches(const KeyFrame& kf1, const KeyFrame& kf2, const std::vector<MapPoint*>& matches,
                      std::vector<loop::PointPair>& pairs, std::vector<std::size_t>& index1) {
  pairs.clear();
  index1.clear();
  for (std::size_t i = 0; i < matches.size(); ++i) {
    MapPoint* p2 = matches[i];
    MapPoint* p1 = kf1.point(i);
    if (!p2 || !p1 || p1->isBad() || p2->isBad()) continue;
    const long i2 = p2->indexIn(&kf2);
    if (i2 < 0) continue;
    pairs.push_back(makePair(kf1, i, kf2, static_cast<std::size_t>(i2)));
    index1.push_back(i);
  }
}

// The loop transform's RANSAC and refinement, by the transform's group.
inline bool ransac(const std::vector<loop::PointPair>& pairs, const PinholeCamera<double>& camera, int minInliers,
                   std::mt19937& rng, SE3d& T12, std::vector<char>& inliers) {
  loop::RelativePoseRansacOptions options;
  options.minInliers = minInliers;
  loop::RelativePoseEstimate estimate = loop::estimateRelativePoseRansac(pairs, camera, options, rng);
  T12 = estimate.T12;
  inliers = std::move(estimate.inliers);
  return estimate.found;
}
inline bool ransac(const std::vector<loop::PointPair>& pairs, const PinholeCamera<double>& camera, int minInliers,
                   std::mt19937& rng, Sim3d& S12, std::vector<char>& inliers) {
  loop::Sim3RansacOptions options;
  options.minInliers = minInliers;
  loop::Sim3Estimate estimate = loop::estimateSim3Ransac(pairs, camera, options, rng);
  S12 = estimate.S12;
  inliers = std::move(estimate.inliers);
  return estimate.found;
}
inline int refine(const std::vector<loop::PointPair>& pairs, const PinholeCamera<double>& camera, SE3d& T12,
                  std::vector<char>& inliers) {
  return loop::refineRelativePose(pairs, camera, T12, inliers);
}
inline int refine(const std::vector<loop::PointPair>& pairs, const PinholeCamera<double>& camera, Sim3d& S12,
                  std::vector<char>& inliers) {
  return loop::refineSim3(pairs, camera, S12, inliers);
}

// The refinement on the camera's pinhole, or through its lens for a camera that observes
// through one (the keypoints moved to the lens's pixels, where their noise is isotropic).
template <CameraModel Camera, class Transform>
int refine(const Camera& camera, std::vector<loop::PointPair>& pairs, Transform& T12, std::vector<char>& inliers) {
  if constexpr (ObservesThroughLens<Camera>) {
    for (loop::PointPair& p : pairs) {
      p.obs1 = camera.lensPixel(p.obs1);
      p.obs2 = camera.lensPixel(p.obs2);
    }
    return loop::refineSim3(pairs, camera.lens, T12, inliers);
  } else {
    return refine(pairs, pinholeOf(camera), T12, inliers);
  }
}

}  // namespace loop_detail

template <SensorConfiguration Sensor>
bool LoopCloser<Sensor>::computeRelativePose(KeyFrame* kf, const std::vector<KeyFrame*>& candidates, LoopCandidate& out) {
  for (KeyFrame* candidate : candidates) {
    std::vector<MapPoint*> matches;
    const int bowMatches = matching::matchKeyFramesByBow(*kf, *candidate, matches);
    if (bowMatches < options_.minBowMatches) continue;
    if (loopTransform(kf, candidate, matches, out)) break;
  }
  if (!out.loopKeyFrame) return false;
  // More matches from the loop keyframe's neighbourhood, seen from the corrected pose.
  std::vector<KeyFrame*> neighbourhood = out.loopKeyFrame->covisibles();
  neighbourhood.insert(neighbourhood.begin(), out.loopKeyFrame);
  const std::vector<MapPoint*> points = distinctGoodPoints(neighbourhood);
  out.loopPoints.insert(out.loopPoints.end(), points.begin(), points.end());
  matching::matchByProjection(camera_, *kf, out.correctedTcw, out.loopPoints, out.matches);
  out.matched = static_cast<int>(std::count_if(out.matches.begin(), out.matches.end(), [](MapPoint* p) { return p; }));
  if (out.matched >= options_.minLoopMatches) return true;
  out = LoopCandidate{};
  return false;
}

template <SensorConfiguration Sensor>
bool LoopCloser<Sensor>::loopTransform(KeyFrame* kf, KeyFrame* candidate, const std::vector<MapPoint*>& matches,
                                       LoopCandidate& out) {
  const PinholeCamera<double>& pinhole = pinholeOf(camera_);
  std::vector<loop::PointPair> pairs;
  std::vector<std::size_t> index1;
  loop_detail::pairsFromMatches(*kf, *candidate, matches, pairs, index1);
  Correction T12;  // camera 1 (kf) from camera 2 (candidate)
  std::vector<char> inliers;
  if (!loop_detail::ransac(pairs, pinhole, options_.minPoseInliers, rng_, T12, inliers)) return false;
  // Guided matching from the RANSAC inliers, then refinement over every match.
  std::vector<MapPoint*> guided(kf->size(), nullptr);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (inliers[k]) guided[index1[k]] = matches[index1[k]];
  if constexpr (Sensor::kMetricScale) {
    matching::matchByRelativePose(camera_, *kf, *candidate, T12, guided);
  } else {
    matching::matchBySim3(camera_, *kf, *candidate, T12, guided);
  }
  loop_detail::pairsFromMatches(*kf, *candidate, guided, pairs, index1);
  inliers.assign(pairs.size(), 1);
  if (loop_detail::refine(camera_, pairs, T12, inliers) < options_.minPoseInliers) return false;
  out.loopKeyFrame = candidate;
  if constexpr (Sensor::kMetricScale) {
    out.correctedTcw = T12 * candidate->Tcw();
    out.correctedScw = out.correctedTcw;
  } else {
    // The current keyframe's pose in the loop side's world and scale, S_cw = S_cl·T_lw; its
    // rigid part (t / s) puts the loop side's points in the image, projections being scale-free.
    out.correctedScw = T12 * Sim3d(candidate->Tcw());
    out.correctedTcw = loop_detail::rigidPart(out.correctedScw);
  }
  out.matches.assign(kf->size(), nullptr);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (inliers[k]) out.matches[index1[k]] = guided[index1[k]];
  return true;
}

}  // namespace orbis
