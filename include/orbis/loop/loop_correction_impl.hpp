// orbis/loop/loop_correction_impl.hpp — the loop correction half of LoopCloser<Sensor>: loop
// fusion, essential graph, full BA and its merge.
//
// Contract: included by loop_closer.hpp only; see there.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <type_traits>

#include "orbis/loop/loop_closer.hpp"
#include "orbis/map/map_bundle_adjustment.hpp"
#include "orbis/map/map_matching.hpp"
#include "orbis/optim/pose_graph.hpp"
#include "orbis/util/thread_scheduling.hpp"

namespace orbis {

namespace loop_detail {

// A corrected pose as the keyframe stores it: itself, or a similarity's rigid part [R | t / s].
inline const SE3d& asPose(const SE3d& Tcw) { return Tcw; }
inline SE3d asPose(const Sim3d& Scw) { return rigidPart(Scw); }

inline MapPoint* followReplacements(MapPoint* p) {
  while (p && p->isBad() && p->replacement()) p = p->replacement();
  return p && !p->isBad() ? p : nullptr;
}

}  // namespace loop_detail

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::pauseMapping() {
  if (!options_.threaded || !mapper_) return;  // deterministic: mapping is idle between calls
  mapper_->requestStop();
  while (!mapper_->isStopped() && !worker_.finishing()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::resumeMapping() {
  if (options_.threaded && mapper_) mapper_->release();
}

template <SensorConfiguration Sensor>
int LoopCloser<Sensor>::fuseAcrossLoop(KeyFrame* kf, LoopCandidate& loop, Fusion& fusion) {
  auto& [nonCorrected, corrected, loopLinks, correctedBy] = fusion;
  int fused = 0;
  std::lock_guard lock(map_.mutex());
  kf->updateConnections();
  // The current keyframe and its neighbours move rigidly with the loop transform (metric), or
  // by the loop's similarity (monocular): S_iw' = T_ic·S_cw', so their scale drift goes too.
  std::vector<KeyFrame*> connected{kf};
  for (KeyFrame* n : kf->covisibles())
    if (!n->isBad()) connected.push_back(n);
  const SE3d Twc = kf->Twc();
  for (KeyFrame* k : connected) {
    nonCorrected[k] = k->Tcw();
    corrected[k] = k == kf ? loop.correctedScw : Correction(k->Tcw() * Twc) * loop.correctedScw;
  }
  for (const auto& [k, Scw] : corrected) {
    const Correction Swc_corrected = Scw.inverse();
    const SE3d& Tcw_old = nonCorrected[k];
    // A point leaves its camera at the old pose and re-enters the world by the correction.
    for (MapPoint* p : k->goodPoints()) {
      if (!correctedBy.emplace(p, k).second) continue;
      p->setPosition(Swc_corrected * (Tcw_old * p->position()));
    }
    k->setPose(loop_detail::asPose(Scw));
  }
  for (const auto& [p, k] : correctedBy) p->updateNormalAndDepth();
  for (KeyFrame* k : connected) k->updateConnections();

  // Loop fusion: the current keyframe's matches become the loop side's points.
  for (std::size_t i = 0; i < loop.matches.size(); ++i) {
    MapPoint* loopPoint = loop_detail::followReplacements(loop.matches[i]);
    if (!loopPoint) continue;
    MapPoint* own = kf->point(i);
    if (own && !own->isBad()) {
      if (own != loopPoint) {
        own->replaceWith(loopPoint);
        ++fused;
      }
    } else if (!loopPoint->isObservedBy(kf)) {
      kf->setPoint(i, loopPoint);
      loopPoint->addObservation(kf, i);
      loopPoint->computeDistinctiveDescriptor();
    }
  }
  // Duplicates in the neighbourhood, now that both sides agree.
  std::vector<MapPoint*> loopPoints;
  for (MapPoint* p : loop.loopPoints)
    if (MapPoint* q = loop_detail::followReplacements(p)) loopPoints.push_back(q);
  for (KeyFrame* k : connected)
    if (!k->isBad()) fused += matching::fuse(camera_, *k, loopPoints, 4.0f);

  // Links the fusion created between the two sides of the loop.
  for (KeyFrame* k : connected) {
    if (k->isBad()) continue;
    const std::vector<KeyFrame*> previous = k->covisibles();
    k->updateConnections();
    std::set<KeyFrame*, ById> links = k->connectedSet();
    for (KeyFrame* n : previous) links.erase(n);
    for (KeyFrame* n : connected) links.erase(n);
    if (!links.empty()) loopLinks[k] = std::move(links);
  }
  loop.loopKeyFrame->addLoopEdge(kf);
  kf->addLoopEdge(loop.loopKeyFrame);
  return fused;
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::correctLoop(KeyFrame* kf, LoopCandidate& loop) {
  // A full BA still running would merge a map this correction has already moved.
  stopFullBundleAdjustment();
  pauseMapping();
  KeyFrame* loopKf = loop.loopKeyFrame;
  Fusion fusion;
  fuseAcrossLoop(kf, loop, fusion);
  optimiseEssentialGraph(kf, loopKf, fusion.nonCorrected, fusion.corrected, fusion.loopLinks, fusion.correctedBy);
  anyLoop_ = true;
  lastLoopKeyFrame_ = kf->id;
  LoopClosureEvent event{kf->id, loopKf->id, kf->frameIndex, loop.matched};
  if constexpr (!Sensor::kMetricScale) event.scale = loop.correctedScw.scale();
  {
    std::lock_guard lock(eventsMutex_);
    events_.push_back(event);
  }
  char line[200];
  std::snprintf(line, sizeof line, "loop closed: keyframe %llu <-> keyframe %llu (frame %llu), %d inliers",
                static_cast<unsigned long long>(event.current), static_cast<unsigned long long>(event.loop),
                static_cast<unsigned long long>(event.frameIndex), event.inliers);
  if constexpr (!Sensor::kMetricScale) {
    const std::size_t used = std::strlen(line);
    std::snprintf(line + used, sizeof line - used, ", Sim(3) scale %.4f", event.scale);
  }
  report(line);
  resumeMapping();
  if (options_.fullBundleAdjustment) startFullBundleAdjustment(kf->mapId());
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::optimiseEssentialGraph(KeyFrame* kf, KeyFrame* loopKf, const PoseMap& nonCorrected,
                                                const CorrectionMap& corrected, const LinkMap& loopLinks,
                                                const PointCorrectors& correctedBy) {
  using Edge = std::conditional_t<Sensor::kMetricScale, optim::PoseGraphEdgeSE3, optim::PoseGraphEdgeSim3>;
  std::vector<KeyFrame*> keyFrames;
  std::vector<Correction> poses, before;
  std::vector<char> fixed;
  std::vector<Edge> edges;
  {
    std::lock_guard lock(map_.mutex());
    keyFrames = map_.keyFrames(kf->mapId());
    // A keyframe's pose after the loop moved it: its pose for a metric sensor; for monocular the
    // similarity the correction gave it (its pose alone has lost the scale), else its pose at
    // scale 1.
    auto correctedPose = [&](KeyFrame* k) {
      if constexpr (!Sensor::kMetricScale) {
        if (const auto it = corrected.find(k); it != corrected.end()) return it->second;
      }
      return Correction(k->Tcw());
    };
    std::map<const KeyFrame*, int> index;
    for (KeyFrame* k : keyFrames) {
      index[k] = static_cast<int>(poses.size());
      poses.push_back(correctedPose(k));
      fixed.push_back(k == loopKf ? 1 : 0);
    }
    before = poses;
    // The pose a keyframe had before the loop moved it: the measurement of its old edges.
    auto oldPose = [&](KeyFrame* k) {
      const auto it = nonCorrected.find(k);
      return Correction(it != nonCorrected.end() ? it->second : k->Tcw());
    };
    std::set<std::pair<int, int>> inserted;
    auto addEdge = [&](KeyFrame* a, KeyFrame* b, const Correction& Taw, const Correction& Tbw) {
      const auto ia = index.find(a), ib = index.find(b);
      if (ia == index.end() || ib == index.end()) return;
      const auto key = std::minmax(ia->second, ib->second);
      if (!inserted.insert(key).second) return;
      edges.push_back({ia->second, ib->second, Taw * Tbw.inverse(), 1.0});
    };
    // New loop links, measured with the corrected poses (they are what the loop says).
    for (const auto& [k, links] : loopLinks)
      for (KeyFrame* n : links) {
        if ((k != kf || n != loopKf) && k->weight(n) < options_.essentialGraphMinWeight) continue;
        addEdge(k, n, correctedPose(k), correctedPose(n));
      }
    for (KeyFrame* k : keyFrames) {
      const Correction Tkw = oldPose(k);
      if (KeyFrame* parent = k->parent(); parent && !parent->isBad()) addEdge(k, parent, Tkw, oldPose(parent));
      for (KeyFrame* l : k->loopEdges())
        if (!l->isBad() && l->id < k->id) addEdge(k, l, Tkw, oldPose(l));
      for (KeyFrame* n : k->covisiblesWithWeightAtLeast(options_.essentialGraphMinWeight)) {
        if (n->isBad() || n->id >= k->id || n == k->parent() || k->hasChild(n) || k->loopEdges().count(n)) continue;
        addEdge(k, n, Tkw, oldPose(n));
      }
    }
  }
  optim::optimizePoseGraph(poses, fixed, edges);

  std::lock_guard lock(map_.mutex());
  std::map<const KeyFrame*, std::size_t> index;
  for (std::size_t i = 0; i < keyFrames.size(); ++i) index[keyFrames[i]] = i;
  // Points move with the keyframe that last corrected them: the loop's corrector, else their
  // reference keyframe. Through the similarities for monocular: into that keyframe's camera at
  // the scale it had, back out at the scale the graph gave it.
  const std::vector<MapPoint*> points = map_.mapPoints(kf->mapId());
  for (MapPoint* p : points) {
    const auto c = correctedBy.find(p);
    const KeyFrame* ref = c != correctedBy.end() ? c->second : p->reference();
    const auto it = ref ? index.find(ref) : index.end();
    if (it == index.end()) continue;
    const std::size_t i = it->second;
    p->setPosition(poses[i].inverse() * (before[i] * p->position()));
  }
  for (std::size_t i = 0; i < keyFrames.size(); ++i)
    if (!keyFrames[i]->isBad()) keyFrames[i]->setPose(loop_detail::asPose(poses[i]));
  for (MapPoint* p : points) p->updateNormalAndDepth();
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::stopFullBundleAdjustment() {
  if (!fullBaThread_.joinable()) return;
  abortFullBa_ = true;
  fullBaThread_.join();
  abortFullBa_ = false;
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::startFullBundleAdjustment(std::uint32_t mapId) {
  stopFullBundleAdjustment();
  fullBaMap_ = mapId;
  fullBaRunning_ = true;
  if (!options_.threaded) {
    runFullBundleAdjustment();
    fullBaRunning_ = false;
    return;
  }
  fullBaThread_ = std::thread([this] {
    nameThisThread("orbis-full-ba");
    if (options_.backgroundPriority) lowerThisThreadPriority();
    runFullBundleAdjustment();
    fullBaRunning_ = false;
  });
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::runFullBundleAdjustment() {
  FullBundleAdjustmentResult result;
  {
    ScopedStage stage(timer_, "loop: full BA");
    result = fullBundleAdjustment<typename Sensor::RobustKernel>(camera_, map_, options_.fullBundleAdjustmentIterations,
                                                                 &abortFullBa_, fullBaMap_);
  }
  if (result.aborted || abortFullBa_) return;
  pauseMapping();
  {
    ScopedStage stage(timer_, "loop: full BA merge");
    std::lock_guard lock(map_.mutex());
    // Keyframes: optimised ones take their new pose; the others (created meanwhile) follow their
    // spanning-tree parent, visited from the root down.
    // Only the optimised map's: the other maps of the atlas are in frames of their own.
    const std::vector<KeyFrame*> keyFrames = map_.keyFrames(fullBaMap_);
    PoseMap before;
    for (KeyFrame* k : keyFrames) before[k] = k->Tcw();
    std::vector<KeyFrame*> stack;
    for (KeyFrame* k : keyFrames)
      if (!k->parent()) stack.push_back(k);  // the roots, in id order (merged maps have several)
    std::set<KeyFrame*, ById> visited;
    while (!stack.empty()) {
      KeyFrame* k = stack.back();
      stack.pop_back();
      if (!visited.insert(k).second) continue;
      if (const auto it = result.keyFramePoses.find(k->id); it != result.keyFramePoses.end()) {
        k->setPose(it->second);
      } else if (KeyFrame* parent = k->parent(); parent && before.count(parent) && before.count(k)) {
        // T_kw' = T_kp · T_pw', with T_kp as it was before the merge.
        k->setPose(before[k] * before[parent].inverse() * parent->Tcw());
      }
      for (KeyFrame* child : k->children())
        if (!child->isBad()) stack.push_back(child);
    }
    // Points: optimised ones take their new position, the others follow their reference.
    for (MapPoint* p : map_.mapPoints(fullBaMap_)) {
      if (const auto it = result.pointPositions.find(p->id); it != result.pointPositions.end()) {
        p->setPosition(it->second);
      } else if (KeyFrame* ref = p->reference(); ref && before.count(ref)) {
        p->setPosition(ref->Tcw().inverse() * (before[ref] * p->position()));
      }
      p->updateNormalAndDepth();
    }
  }
  resumeMapping();
}

}  // namespace orbis
