// orbis/loop/loop_merge_impl.hpp — merging two maps of the atlas (issue 32), the map-merge half
// of LoopCloser<Sensor>.
//
// Contract: included by loop_closer.hpp only; see there. mergeMaps(kf, place) takes a keyframe
// of the active map and a verified place of another map (the same candidate record a loop uses:
// kf's pose in the other map's frame, its matches there). The smaller map (in keyframes; the
// active one on a tie) is moved into the other's frame by the verified transform (a similarity
// for monocular, whose scale then follows the kept map), relabelled as it, and the seam is then
// handled as a loop is: the current keyframe's neighbourhood corrected, duplicated points fused,
// loop links and a loop edge added, the essential graph of the merged map optimised with the
// other side's keyframe fixed, a welding local BA around the current keyframe, and full BA of
// the merged map in the background. Local mapping is paused throughout; tracking only waits for
// the map mutex, which each step holds as a loop correction's steps do.
#pragma once

#include <chrono>
#include <cstdio>

#include "orbis/loop/loop_closer.hpp"
#include "orbis/map/map_bundle_adjustment.hpp"

namespace orbis {

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::moveMap(std::uint32_t moved, const Correction& S) {
  // Points first: a point's map is its reference keyframe's, which the relabelling changes.
  for (MapPoint* p : map_.mapPoints(moved)) p->setPosition(S * p->position());
  const Correction Sinv = S.inverse();
  for (KeyFrame* k : map_.keyFrames(moved)) k->setPose(loop_detail::asPose(Correction(k->Tcw()) * Sinv));
  for (MapPoint* p : map_.mapPoints(moved)) p->updateNormalAndDepth();
}

template <SensorConfiguration Sensor>
void LoopCloser<Sensor>::mergeMaps(KeyFrame* kf, LoopCandidate& place) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  stopFullBundleAdjustment();  // it would write back poses of a map this merge moves
  pauseMapping();
  KeyFrame* otherKf = place.loopKeyFrame;
  MapMergeEvent event;
  {
    std::lock_guard lock(map_.mutex());
    event.current = kf->id;
    event.other = otherKf->id;
    event.frameIndex = kf->frameIndex;
    event.otherFrameIndex = otherKf->frameIndex;
    event.activeMap = kf->mapId();
    event.otherMap = otherKf->mapId();
    event.inliers = place.matched;
    // The other map's world from the active map's: x_other = S·x_active, since kf sees a point
    // at Tcw·x_active = Scw'·x_other.
    const Correction otherFromActive = Correction(place.correctedScw).inverse() * Correction(kf->Tcw());
    const std::size_t activeKeyFrames = map_.keyFrameCount(event.activeMap);
    const std::size_t otherKeyFrames = map_.keyFrameCount(event.otherMap);
    const bool moveActive = activeKeyFrames <= otherKeyFrames;
    event.movedMap = moveActive ? event.activeMap : event.otherMap;
    event.keptMap = moveActive ? event.otherMap : event.activeMap;
    const Correction S = moveActive ? otherFromActive : otherFromActive.inverse();
    event.movedKeyFrames = moveActive ? activeKeyFrames : otherKeyFrames;
    event.movedPoints = map_.mapPointCount(event.movedMap);
    if constexpr (!Sensor::kMetricScale) event.scale = S.scale();
    moveMap(event.movedMap, S);
    map_.mergeInto(event.movedMap, event.keptMap, event.scale);
    map_.setActiveMap(event.keptMap);
    // kf's pose in the merged frame: where the place put it when kf's map moved (its pose now),
    // else unchanged (the other map came to it).
    if (!moveActive) {
      place.correctedScw = Correction(kf->Tcw());
      place.correctedTcw = kf->Tcw();
    }
    const Eigen::Quaterniond q(S.so3().matrix());
    event.rotation = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
    event.translation = S.translation();
  }
  // The seam, as a loop: fusion, links, essential graph with the other side fixed.
  Fusion fusion;
  event.fusedPoints = fuseAcrossLoop(kf, place, fusion);
  optimiseEssentialGraph(kf, otherKf, fusion.nonCorrected, fusion.corrected, fusion.loopLinks, fusion.correctedBy);
  // Welding BA: the current keyframe, its neighbours on both sides of the seam and their points.
  localBundleAdjustment<typename Sensor::RobustKernel>(camera_, map_, kf, nullptr);
  anyLoop_ = true;
  lastLoopKeyFrame_ = kf->id;
  event.milliseconds = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  {
    std::lock_guard lock(eventsMutex_);
    merges_.push_back(event);
  }
  char line[240];
  std::snprintf(line, sizeof line,
                "maps merged: keyframe %llu (map %u) <-> keyframe %llu (map %u) at frame %llu, %d inliers, map %u "
                "(%zu keyframes) moved into map %u",
                static_cast<unsigned long long>(event.current), event.activeMap,
                static_cast<unsigned long long>(event.other), event.otherMap,
                static_cast<unsigned long long>(event.frameIndex), event.inliers, event.movedMap, event.movedKeyFrames,
                event.keptMap);
  report(line);
  resumeMapping();
  if (options_.fullBundleAdjustment) startFullBundleAdjustment(event.keptMap);
}

}  // namespace orbis
