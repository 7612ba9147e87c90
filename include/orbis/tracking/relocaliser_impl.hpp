// orbis/tracking/relocaliser_impl.hpp — bodies of Relocaliser<Sensor> (relocaliser.hpp).
//
// Contract: included by relocaliser.hpp only; see there.
#pragma once

#include <algorithm>
#include <set>

#include "orbis/map/map_covisibility.hpp"
#include "orbis/map/map_matching.hpp"
#include "orbis/tracking/pose_optimizer.hpp"
#include "orbis/tracking/relocaliser.hpp"

namespace orbis {

namespace relocaliser_detail {

// Drops outlier matches so later searches may reuse their keypoints; returns the matches kept.
template <CameraModel Camera>
int dropOutliers(Frame<Camera>& frame) {
  int kept = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (!frame.points[i]) continue;
    if (frame.outlier[i]) {
      frame.points[i] = nullptr;
      frame.outlier[i] = 0;
    } else {
      ++kept;
    }
  }
  return kept;
}

template <CameraModel Camera>
std::set<MapPoint*, ById> matchedPoints(const Frame<Camera>& frame) {
  std::set<MapPoint*, ById> found;
  for (MapPoint* p : frame.points)
    if (p) found.insert(p);
  return found;
}

}  // namespace relocaliser_detail

template <SensorConfiguration Sensor>
bool Relocaliser<Sensor>::tryCandidate(FrameT& frame, const KeyFrame& kf, const std::vector<MapPoint*>& bowMatches,
                               std::mt19937_64& rng) const {
  const FrameFeatures& f = *frame.features;
  Vector3dList world;
  Vector2dList pixels;
  std::vector<float> sigma2;
  std::vector<std::size_t> keypointOf;
  for (std::size_t i = 0; i < bowMatches.size(); ++i) {
    const MapPoint* p = bowMatches[i];
    if (!p || p->isBad()) continue;
    world.push_back(p->position());
    pixels.emplace_back(f.keypointsUn[i].u, f.keypointsUn[i].v);
    sigma2.push_back(f.scales.sigma2[static_cast<std::size_t>(f.keypointsUn[i].octave)]);
    keypointOf.push_back(i);
  }
  PnpRansacParams params = options_.ransac;
  // As ORB-SLAM: at least half of the matches must agree (expected inlier ratio 0.5).
  params.minInliers = std::max(params.minInliers, static_cast<int>(0.5 * static_cast<double>(world.size())));
  const PnpRansacResult ransac = solvePnpRansac(world, pixels, sigma2, pinholeOf(*frame.camera), params, rng);
  if (!ransac.found) return false;

  frame.resetMatches();
  frame.Tcw = ransac.Tcw;
  for (std::size_t k = 0; k < keypointOf.size(); ++k)
    if (ransac.inlier[k]) frame.points[keypointOf[k]] = bowMatches[keypointOf[k]];
  int good = optimizePose<typename Sensor::RobustKernel>(frame);
  if (good < 10) return false;
  relocaliser_detail::dropOutliers(frame);

  // Too few: look for more points around their projections (wide, then narrow). ORB-SLAM2 looks
  // only at the candidate's own points; orbis also at those of its best covisible keyframes, the
  // neighbourhood the tracker checks the pose against next. A camera that has turned on while
  // tracking was lost sees the candidate's view only in part: on the rendered loop, 10 black
  // frames later, the one candidate found had 41-44 of its points confirmed, below the 50 asked.
  std::vector<const KeyFrame*> neighbourhood{&kf};
  for (const KeyFrame* n : kf.bestCovisibles(kCovisiblesSearched))
    if (!n->isBad()) neighbourhood.push_back(n);
  auto searchNeighbourhood = [&](float radius, int maxDistance) {
    int found = 0;
    for (const KeyFrame* k : neighbourhood)
      found += matching::matchFromKeyFrame(frame, *k, relocaliser_detail::matchedPoints(frame), radius, maxDistance);
    return found;
  };
  if (good < options_.acceptInliers) {
    int extra = searchNeighbourhood(10.f, 100);
    if (good + extra >= options_.acceptInliers) {
      good = optimizePose<typename Sensor::RobustKernel>(frame);
      if (good > 30 && good < options_.acceptInliers) {
        relocaliser_detail::dropOutliers(frame);
        extra = searchNeighbourhood(3.f, 64);
        if (good + extra >= options_.acceptInliers) good = optimizePose<typename Sensor::RobustKernel>(frame);
      }
      relocaliser_detail::dropOutliers(frame);
    }
  }
  return good >= options_.acceptInliers;
}

template <SensorConfiguration Sensor>
bool Relocaliser<Sensor>::relocalise(FrameT& frame) {
  ++stats_.attempts;
  const std::vector<bow::PlaceCandidate> candidates =
      database_.detectRelocalisationCandidates(frame.bow, MapCovisibility(map_));
  stats_.lastCandidates = candidates.size();
  std::mt19937_64 rng(options_.seed * 0x9E3779B97F4A7C15ull + frame.index);
  for (const bow::PlaceCandidate& c : candidates) {
    const KeyFrame* kf = map_.keyFrame(c.keyframe);
    if (!kf || kf->isBad()) continue;
    std::vector<MapPoint*> matches;
    if (matching::matchByBow(*kf, frame, matches, options_.bowRatio, true) < options_.minBowMatches) continue;
    if (tryCandidate(frame, *kf, matches, rng)) {
      ++stats_.successes;
      stats_.lastKeyFrame = kf->id;
      return true;
    }
  }
  frame.resetMatches();
  return false;
}

}  // namespace orbis
