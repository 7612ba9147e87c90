// orbis/map/map_matching_impl.hpp — bodies of the searches declared in map_matching.hpp.
//
// Contract: included by map_matching.hpp only; see there.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>

#include "orbis/map/map_matching.hpp"
#include "orbis/util/prefetch.hpp"

namespace orbis::matching {

namespace detail {

// A keypoint's slot holds a map point (not a tracking-only point without observations, which a
// better match may replace).
inline bool matchedToMapPoint(const MapPoint* slot) { return slot && slot->observationCount() > 0; }

// The camera's observation of a camera-frame point in front of it: (u, v) and, for a stereo
// camera, the predicted right coordinate (-1 otherwise).
template <CameraModel Camera>
Eigen::Vector3d projectWithRight(const Camera& camera, const Eigen::Vector3d& pc) {
  if constexpr (StereoCameraModel<Camera>) {
    return camera.project(pc);
  } else {
    const Eigen::Vector2d uv = camera.project(pc);
    return {uv.x(), uv.y(), -1.0};
  }
}

// Where a camera's pixel noise is isotropic: the observation itself, or for a camera observing
// through a lens the lens pixel of the plane observation (of the camera-frame point pc whose plane
// projection is planePx).
template <CameraModel Camera>
Eigen::Vector2d noisePixel(const Camera& camera, const Eigen::Vector2d& planePx) {
  if constexpr (ObservesThroughLens<Camera>) return camera.lensPixel(planePx);
  else return planePx;
}
template <CameraModel Camera>
Eigen::Vector2d noisePixel(const Camera& camera, const Eigen::Vector3d& pc, const Eigen::Vector2d& planePx) {
  if constexpr (ObservesThroughLens<Camera>) return camera.lens.project(pc);
  else return planePx;
}

}  // namespace detail

template <CameraModel Camera>
bool projectIntoFrame(const Camera& camera, const MapIntrinsics& bounds, const MapPoint& point, const SE3d& Tcw,
                      const Eigen::Vector3d& cameraCentre, const ScaleLevels& levels, Projection& out) {
  const Eigen::Vector3d pw = point.position();
  const Eigen::Vector3d pc = Tcw * pw;
  if (pc.z() <= 0) return false;
  const Eigen::Vector3d obs = detail::projectWithRight(camera, pc);
  const double u = obs.x(), v = obs.y();
  if (!bounds.inImage(u, v)) return false;
  const Eigen::Vector3d po = pw - cameraCentre;
  const float dist = static_cast<float>(po.norm());
  if (dist < point.minDistanceInvariance() || dist > point.maxDistanceInvariance()) return false;
  const Eigen::Vector3d& n = point.normal();
  const float viewCos = n.norm() > 0 ? static_cast<float>(po.dot(n) / (dist * n.norm())) : 1.f;
  if (viewCos < 0.5f) return false;
  out.u = static_cast<float>(u);
  out.v = static_cast<float>(v);
  out.uRight = StereoCameraModel<Camera> ? static_cast<float>(obs.z()) : -1.f;
  out.level = point.predictScale(dist, levels.levels(), levels.logFactor());
  out.viewCos = viewCos;
  out.windowStretch = searchWindowStretch(camera, pc);
  return true;
}

template <CameraModel Camera>
int matchFromLastFrame(Frame<Camera>& current, const Frame<Camera>& last, float radius, bool checkOrientation) {
  const FrameFeatures& cf = *current.features;
  const ScaleLevels& levels = cf.scales;
  RotationHistogram hist;
  const SE3d& Tcw = current.Tcw;
  const Eigen::Vector3d tlc = last.Tcw * current.cameraCenter();  // current centre in last's frame
  // A stereo camera that moved more than its baseline forward (backward) sees last's points at
  // finer (coarser) levels only.
  constexpr bool kStereo = StereoCameraModel<Camera>;
  double baseline = 0;
  if constexpr (kStereo) baseline = current.camera->bf() / pinholeOf(*current.camera).fx;
  const bool forward = kStereo && tlc.z() > baseline;
  const bool backward = kStereo && -tlc.z() > baseline;
  // The last frame's points are mostly cache misses by now (mapping has written them); asked for
  // one by one in the loop below they came one after another (docs/notes/2026-11-29-speed-slot-bits.md).
  for (const MapPoint* p : last.points)
    if (p) prefetchLines(p, 0, 2);
  int matches = 0;
  for (std::size_t i = 0; i < last.size(); ++i) {
    MapPoint* p = last.points[i];
    if (!p || last.outlier[i] || p->isBad()) continue;
    const Eigen::Vector3d pc = Tcw * p->position();
    if (pc.z() <= 0) continue;
    const Eigen::Vector3d obs = detail::projectWithRight(*current.camera, pc);
    const float u = static_cast<float>(obs.x());
    const float v = static_cast<float>(obs.y());
    if (!current.intrinsics.inImage(u, v)) continue;
    const int lastOctave = last.features->keypointsUn[i].octave;
    const float r = radius * levels.scale[static_cast<std::size_t>(lastOctave)] * searchWindowStretch(*current.camera, pc);
    int minLevel = lastOctave - 1, maxLevel = lastOctave + 1;
    if (forward) { minLevel = lastOctave; maxLevel = levels.levels() - 1; }
    else if (backward) { minLevel = 0; maxLevel = lastOctave; }
    const float uRightPred = static_cast<float>(obs.z());
    // A stereo prediction is checked even when negative (a point nearer than the baseline).
    const NearestTwo n = nearestTwoInArea(cf, p->descriptor(), u, v, r, std::max(0, minLevel), maxLevel, [&](std::size_t j) {
      return detail::matchedToMapPoint(current.points[j]) ||
             (kStereo && cf.uRight[j] >= 0 && std::abs(uRightPred - cf.uRight[j]) > r);
    });
    if (n.best >= 0 && n.bestDistance <= kThHigh) {
      const auto best = static_cast<std::size_t>(n.best);
      current.points[best] = p;
      current.outlier[best] = 0;
      ++matches;
      if (checkOrientation) hist.add(last.features->keypointsUn[i].angle - cf.keypointsUn[best].angle, static_cast<int>(best));
    }
  }
  if (checkOrientation) matches -= hist.clearRejected(current.points);
  return matches;
}

template <CameraModel Camera>
int matchLocalPoints(Frame<Camera>& frame, const std::vector<MapPoint*>& points, const std::vector<Projection>& projections,
                     float radiusFactor, float ratio) {
  std::vector<ProjectionQuery> queries;
  std::vector<MapPoint*> queried;
  queries.reserve(points.size());
  queried.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    MapPoint* p = points[k];
    if (!p || p->isBad()) continue;
    const Projection& pr = projections[k];
    queries.push_back({pr.u, pr.v, pr.uRight, pr.level, pr.viewCos, p->descriptor(), pr.windowStretch});
    queried.push_back(p);
  }
  std::vector<std::uint8_t> taken(frame.size());
  for (std::size_t j = 0; j < frame.size(); ++j) taken[j] = detail::matchedToMapPoint(frame.points[j]) ? 1 : 0;
  std::vector<int> keypointOf;
  const int matches = searchByProjection(*frame.features, std::span<const ProjectionQuery>(queries), radiusFactor, ratio,
                                         taken, keypointOf);
  for (std::size_t q = 0; q < queries.size(); ++q) {
    if (keypointOf[q] < 0) continue;
    const auto j = static_cast<std::size_t>(keypointOf[q]);
    frame.points[j] = queried[q];
    frame.outlier[j] = 0;
  }
  return matches;
}

template <CameraModel Camera>
int matchByBow(const KeyFrame& kf, const Frame<Camera>& frame, std::vector<MapPoint*>& out, float ratio, bool checkOrientation) {
  const FrameFeatures& kff = kf.features();
  const FrameFeatures& ff = *frame.features;
  out.assign(frame.size(), nullptr);
  RotationHistogram hist;
  int matches = 0;
  bow::forEachSharedNode(kf.featureVector(), frame.featureVector, [&](auto kfFeatures, auto frameFeatures) {
    for (std::uint32_t i : kfFeatures) {
      MapPoint* p = kf.point(i);
      if (!p || p->isBad()) continue;
      const NearestTwo n = nearestTwo(ff, kff.descriptors[i], frameFeatures, [&](std::size_t j) { return out[j] != nullptr; });
      if (n.best >= 0 && n.bestDistance <= kThLow && n.bestDistance < ratio * static_cast<float>(n.secondDistance)) {
        const auto best = static_cast<std::size_t>(n.best);
        out[best] = p;
        ++matches;
        if (checkOrientation) hist.add(kff.keypointsUn[i].angle - ff.keypointsUn[best].angle, static_cast<int>(best));
      }
    }
  });
  if (checkOrientation) matches -= hist.clearRejected(out);
  return matches;
}

template <CameraModel Camera>
int matchFromKeyFrame(Frame<Camera>& frame, const KeyFrame& kf, const std::set<MapPoint*, ById>& alreadyFound, float radius,
                      int maxDistance) {
  const FrameFeatures& f = *frame.features;
  const Eigen::Vector3d center = frame.cameraCenter();
  RotationHistogram hist;
  std::vector<int> candidates;
  int matches = 0;
  for (std::size_t i = 0; i < kf.size(); ++i) {
    MapPoint* p = kf.point(i);
    if (!p || p->isBad() || alreadyFound.count(p)) continue;
    const Eigen::Vector3d pc = frame.Tcw * p->position();
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = pinholeOf(*frame.camera).project(pc);
    const float u = static_cast<float>(uv.x());
    const float v = static_cast<float>(uv.y());
    if (!frame.intrinsics.inImage(u, v)) continue;
    const float dist = static_cast<float>((p->position() - center).norm());
    if (dist < p->minDistanceInvariance() || dist > p->maxDistanceInvariance()) continue;
    const int level = p->predictScale(dist, f.scales.levels(), f.scales.logFactor());
    const float r = radius * f.scales.scale[static_cast<std::size_t>(level)] * searchWindowStretch(*frame.camera, pc);
    f.grid.featuresInArea(u, v, r, level - 1, level + 1, candidates);
    const NearestTwo n = nearestTwo(f, p->descriptor(), candidates, [&](std::size_t j) { return frame.points[j] != nullptr; });
    if (n.best >= 0 && n.bestDistance <= maxDistance) {
      const auto best = static_cast<std::size_t>(n.best);
      frame.points[best] = p;
      frame.outlier[best] = 0;
      ++matches;
      hist.add(kf.features().keypointsUn[i].angle - f.keypointsUn[best].angle, static_cast<int>(best));
    }
  }
  matches -= hist.clearRejected(frame.points);
  return matches;
}

template <CameraModel Camera>
std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulation(const Camera& camera, const KeyFrame& kf1,
                                                                      const KeyFrame& kf2, const Eigen::Matrix3d& F12,
                                                                      bool onlyStereo) {
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();
  // Epipole of kf1's centre in kf2: keypoints too close to it have unreliable depth.
  const Eigen::Vector3d c1in2 = kf2.Tcw() * kf1.cameraCenter();
  const Eigen::Vector2d epipole = pinholeOf(camera).project(c1in2);
  std::vector<std::uint8_t> taken2(kf2.size(), 0);
  std::vector<long> matched1(kf1.size(), -1);
  RotationHistogram hist;
  bow::forEachSharedNode(kf1.featureVector(), kf2.featureVector(), [&](auto features1, auto features2) {
    for (std::uint32_t i : features1) {
      if (kf1.point(i)) continue;
      const Keypoint& k1 = f1.keypointsUn[i];
      // x2ᵀ F12 x1 = 0, so the epipolar line of x1 in kf2 is F12 x1; candidates share the node.
      const Eigen::Vector3d line = F12 * Eigen::Vector3d(k1.u, k1.v, 1.0);
      const long best = bestEpipolarPartner(f1, i, f2, features2, line, epipole, onlyStereo,
                                            [&](std::size_t j) { return kf2.point(j) != nullptr || taken2[j]; });
      if (best >= 0) {
        taken2[static_cast<std::size_t>(best)] = 1;
        matched1[i] = best;
        hist.add(k1.angle - f2.keypointsUn[static_cast<std::size_t>(best)].angle, static_cast<int>(i));
      }
    }
  });
  std::vector<int> rejected;
  hist.rejected(rejected);
  for (int i : rejected) matched1[static_cast<std::size_t>(i)] = -1;
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (std::size_t i = 0; i < matched1.size(); ++i)
    if (matched1[i] >= 0) out.emplace_back(i, static_cast<std::size_t>(matched1[i]));
  return out;
}

template <CameraModel Camera>
int fuse(const Camera& camera, KeyFrame& kf, const std::vector<MapPoint*>& points, float radius) {
  const FrameFeatures& f = kf.features();
  const SE3d Tcw = kf.Tcw();
  const Eigen::Vector3d center = kf.cameraCenter();
  std::vector<int> candidates;
  int fused = 0;
  for (MapPoint* p : points) {
    if (!p || p->isBad() || p->isObservedBy(&kf)) continue;
    const Eigen::Vector3d pc = Tcw * p->position();
    if (pc.z() <= 0) continue;
    const Eigen::Vector3d obs = detail::projectWithRight(camera, pc);
    const double u = obs.x(), v = obs.y();
    if (!kf.intrinsics.inImage(u, v)) continue;
    const double ur = obs.z();
    const Eigen::Vector3d po = p->position() - center;
    const float dist = static_cast<float>(po.norm());
    if (dist < p->minDistanceInvariance() || dist > p->maxDistanceInvariance()) continue;
    if (p->normal().norm() > 0 && po.dot(p->normal()) < 0.5 * dist * p->normal().norm()) continue;
    const int level = p->predictScale(dist, f.scales.levels(), f.scales.logFactor());
    const float r = radius * f.scales.scale[static_cast<std::size_t>(level)] * searchWindowStretch(camera, pc);
    f.grid.featuresInArea(static_cast<float>(u), static_cast<float>(v), r, -1, -1, candidates);
    // Candidates on the predicted level or the one below whose reprojection error passes χ²
    // at 95% (2 degrees of freedom, 3 with a right coordinate), in the lens's pixels for a
    // camera that observes through one.
    const Eigen::Vector2d predicted = detail::noisePixel(camera, pc, Eigen::Vector2d(u, v));
    const auto reprojectionTooFar = [&](std::size_t j) {
      const Keypoint& k = f.keypointsUn[j];
      if (k.octave < level - 1 || k.octave > level) return true;
      const Eigen::Vector2d measured = detail::noisePixel(camera, Eigen::Vector2d(k.u, k.v));
      const double ex = predicted.x() - measured.x(), ey = predicted.y() - measured.y();
      const double inv2 = f.scales.invSigma2[static_cast<std::size_t>(k.octave)];
      if (f.uRight[j] >= 0) {
        const double er = ur - f.uRight[j];
        return (ex * ex + ey * ey + er * er) * inv2 > 7.8;
      }
      return (ex * ex + ey * ey) * inv2 > 5.99;
    };
    const NearestTwo n = nearestTwo(f, p->descriptor(), candidates, reprojectionTooFar);
    if (n.best < 0 || n.bestDistance > kThLow) continue;
    const auto j = static_cast<std::size_t>(n.best);
    if (MapPoint* existing = kf.point(j); existing && !existing->isBad()) {
      // Keep the better-observed point; the other is merged into it.
      if (existing->observationCount() > p->observationCount()) p->replaceWith(existing);
      else existing->replaceWith(p);
    } else {
      p->addObservation(&kf, j);
      kf.setPoint(j, p);
    }
    ++fused;
  }
  return fused;
}

}  // namespace orbis::matching
