// orbis/map/keyframe_matching_impl.hpp — bodies of the searches declared in
// keyframe_matching.hpp.
//
// Contract: included by keyframe_matching.hpp only; see there.
#pragma once

#include <cmath>
#include <set>

#include "orbis/map/keyframe_matching.hpp"
#include "orbis/map/map_matching.hpp"

namespace orbis::matching {

namespace keyframe_detail {

// Where a point seen from pose Tcw should appear in `kf`, and the pyramid level it predicts;
// false when it is behind the camera, off the image or outside its scale-invariance range.
// windowStretch: how much the camera's lens widens a matching window there (1: no lens).
// Tcw is an SE3d, or a Sim3d taking another keyframe's world (its map scale) into this camera:
// its inverse's translation is still the camera centre in that world, where the point's scale-
// invariance distances were measured.
template <CameraModel Camera, class Pose>
bool predict(const Camera& camera, const KeyFrame& kf, const Pose& Tcw, const Eigen::Vector3d& world,
             const MapPoint& point, float& u, float& v, int& level, float& windowStretch, bool checkViewAngle) {
  const Eigen::Vector3d pc = Tcw * world;
  if (pc.z() <= 0) return false;
  const Eigen::Vector2d xy = pinholeOf(camera).project(pc);
  const double x = xy.x(), y = xy.y();
  if (!kf.intrinsics.inImage(x, y)) return false;
  const Eigen::Vector3d po = world - Tcw.inverse().translation();
  const auto dist = static_cast<float>(po.norm());
  if (dist < point.minDistanceInvariance() || dist > point.maxDistanceInvariance()) return false;
  if (checkViewAngle && point.normal().norm() > 0 && po.dot(point.normal()) < 0.5 * dist * point.normal().norm())
    return false;
  const ScaleLevels& levels = kf.features().scales;
  level = point.predictScale(dist, levels.levels(), levels.logFactor());
  u = static_cast<float>(x);
  v = static_cast<float>(y);
  windowStretch = searchWindowStretch(camera, pc);
  return true;
}

// Best keypoint of `kf` near (u, v) for `descriptor`, at most `maxDistance` away in Hamming
// distance; -1 when none.
inline long bestInArea(const KeyFrame& kf, float u, float v, int level, float radius, const OrbDescriptor& descriptor,
                int maxDistance, const std::vector<MapPoint*>* taken) {
  const FrameFeatures& f = kf.features();
  const float r = radius * f.scales.scale[static_cast<std::size_t>(level)];
  const NearestTwo n = nearestTwo(f, descriptor, f.grid.featuresInArea(u, v, r, level - 1, level + 1),
                                  [&](std::size_t j) { return taken && (*taken)[j]; });
  return n.best >= 0 && n.bestDistance <= maxDistance ? n.best : -1;
}

}  // namespace keyframe_detail

inline int matchKeyFramesByBow(const KeyFrame& kf1, const KeyFrame& kf2, std::vector<MapPoint*>& matches12, float ratio) {
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();
  matches12.assign(kf1.size(), nullptr);
  std::vector<char> taken2(kf2.size(), 0);
  RotationHistogram hist;
  int matches = 0;
  bow::forEachSharedNode(kf1.featureVector(), kf2.featureVector(), [&](auto features1, auto features2) {
    for (std::uint32_t i : features1) {
      MapPoint* p1 = kf1.point(i);
      if (!p1 || p1->isBad()) continue;
      const NearestTwo n = nearestTwo(f2, f1.descriptors[i], features2, [&](std::size_t j) {
        const MapPoint* p2 = kf2.point(j);
        return taken2[j] || !p2 || p2->isBad();
      });
      if (n.best >= 0 && n.bestDistance < kThLow && n.bestDistance < ratio * static_cast<float>(n.secondDistance)) {
        const auto j = static_cast<std::size_t>(n.best);
        matches12[i] = kf2.point(j);
        taken2[j] = 1;
        hist.add(f1.keypointsUn[i].angle - f2.keypointsUn[j].angle, static_cast<int>(i));
        ++matches;
      }
    }
  });
  matches -= hist.clearRejected(matches12);
  return matches;
}

namespace keyframe_detail {

// kf2's points into kf1 through T1w_via2, kf1's into kf2 through T2w_via1; the pairs both
// directions chose are added to matches12.
template <CameraModel Camera, class Pose>
int matchBothWays(const Camera& camera, const KeyFrame& kf1, const KeyFrame& kf2, const Pose& T1w_via2,
                  const Pose& T2w_via1, std::vector<MapPoint*>& matches12, float radius) {
  std::set<MapPoint*, ById> alreadyMatched;
  for (MapPoint* p : matches12)
    if (p) alreadyMatched.insert(p);

  // kf2's points into kf1.
  std::vector<long> match1to2(kf1.size(), -1);
  for (std::size_t j = 0; j < kf2.size(); ++j) {
    MapPoint* p = kf2.point(j);
    if (!p || p->isBad() || alreadyMatched.count(p)) continue;
    float u, v, stretch;
    int level;
    if (!predict(camera, kf1, T1w_via2, p->position(), *p, u, v, level, stretch, false)) continue;
    const long i = bestInArea(kf1, u, v, level, radius * stretch, p->descriptor(), kThHigh, nullptr);
    if (i >= 0 && !matches12[static_cast<std::size_t>(i)]) match1to2[static_cast<std::size_t>(i)] = static_cast<long>(j);
  }
  // kf1's points into kf2; keep the pairs both directions chose.
  int added = 0;
  for (std::size_t i = 0; i < kf1.size(); ++i) {
    MapPoint* p = kf1.point(i);
    if (!p || p->isBad() || matches12[i] || match1to2[i] < 0) continue;
    float u, v, stretch;
    int level;
    if (!predict(camera, kf2, T2w_via1, p->position(), *p, u, v, level, stretch, false)) continue;
    const long j = bestInArea(kf2, u, v, level, radius * stretch, p->descriptor(), kThHigh, nullptr);
    if (j != match1to2[i]) continue;
    matches12[i] = kf2.point(static_cast<std::size_t>(j));
    ++added;
  }
  return added;
}

}  // namespace keyframe_detail

template <CameraModel Camera>
int matchByRelativePose(const Camera& camera, const KeyFrame& kf1, const KeyFrame& kf2, const SE3d& T12, std::vector<MapPoint*>& matches12,
                        float radius) {
  const SE3d T21 = T12.inverse();
  const SE3d T1w = kf1.Tcw(), T2w = kf2.Tcw();
  // Pose of camera 1 (resp. 2) expressed so the other keyframe's world points land in it.
  const SE3d T1w_via2 = T12 * T2w;  // world (as kf2 sees it) -> camera 1
  const SE3d T2w_via1 = T21 * T1w;  // world (as kf1 sees it) -> camera 2
  return keyframe_detail::matchBothWays(camera, kf1, kf2, T1w_via2, T2w_via1, matches12, radius);
}

template <CameraModel Camera>
int matchBySim3(const Camera& camera, const KeyFrame& kf1, const KeyFrame& kf2, const Sim3d& S12,
                std::vector<MapPoint*>& matches12, float radius) {
  // Each keyframe's world, at its own map scale, into the other camera.
  const Sim3d S1w_via2 = S12 * Sim3d(kf2.Tcw());
  const Sim3d S2w_via1 = S12.inverse() * Sim3d(kf1.Tcw());
  return keyframe_detail::matchBothWays(camera, kf1, kf2, S1w_via2, S2w_via1, matches12, radius);
}

template <CameraModel Camera>
int matchByProjection(const Camera& camera, const KeyFrame& kf, const SE3d& Tcw, const std::vector<MapPoint*>& points,
                      std::vector<MapPoint*>& matches, float radius) {
  std::set<MapPoint*, ById> alreadyMatched;
  for (MapPoint* p : matches)
    if (p) alreadyMatched.insert(p);
  int added = 0;
  for (MapPoint* p : points) {
    if (!p || p->isBad() || alreadyMatched.count(p)) continue;
    float u, v, stretch;
    int level;
    if (!keyframe_detail::predict(camera, kf, Tcw, p->position(), *p, u, v, level, stretch, true)) continue;
    const long i = keyframe_detail::bestInArea(kf, u, v, level, radius * stretch, p->descriptor(), kThLow, &matches);
    if (i < 0) continue;
    matches[static_cast<std::size_t>(i)] = p;
    alreadyMatched.insert(p);
    ++added;
  }
  return added;
}

}  // namespace orbis::matching
