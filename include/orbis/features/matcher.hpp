// orbis/features/matcher.hpp — the descriptor-search kernels of every matching search, and the
// searches that work on plain query arrays (ORB-SLAM's searches).
//
// Contract: nothing throws; everything works on FrameFeatures and indices (no map objects), so
// the map-level searches of map/map_matching.hpp and map/keyframe_matching.hpp are adapters
// over these kernels and searches. Thresholds are ORB-SLAM's named constants: kThHigh = 100 and
// kThLow = 50 (Hamming bits), nearest/second-nearest ratios kRatioLoose = 0.9 and kRatioStrict
// = 0.75 (callers pass the one their stage uses), and the rotation histogram of
// rotation_histogram.hpp. Everything is a template over the distance policy (HammingDistance by
// default) so the inner loop is inlined.
// Kernels:
//  - nearestTwo: the nearest and second-nearest keypoints to a query descriptor among candidate
//    keypoint indices (a grid window, a vocabulary node), with their distances and octaves;
//    a predicate leaves candidates out; ties keep the earlier candidate.
//  - rightCoordinateDisagrees: the stereo check, a predicted and an observed right coordinate
//    (both present) more than the search radius apart.
//  - bestEpipolarPartner: the best candidate along an epipolar line (ORB-SLAM's
//    SearchForTriangulation test); fundamentalFromPose builds that line's F21.
// Searches (each allocates only its per-call working buffers: taken marks, grid candidates):
//  - searchByProjection: map points predicted in the frame (pixel, right coordinate, octave,
//    viewing-angle cosine); window radius 2.5 px (4 px when the viewing angle differs by more
//    than ~3.6 degrees from the mean) x th x the octave's scale, octaves [o-1, o], best/second
//    ratio when both lie on one octave, stereo coordinate check; one query per keypoint.
//    Tracking's local-map search (matching::matchLocalPoints) runs it.
//  - searchForInitialization: monocular initialisation; level-0 keypoints of frame 1 searched in a
//    square window around their previous match in frame 2, kThLow, ratio, one-to-one, rotation.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/features/rotation_histogram.hpp"

namespace orbis {

namespace matching {
// @{
// ORB-SLAM's descriptor distance thresholds (high, low) and nearest-neighbour ratios (loose,
// strict).
inline constexpr int kThHigh = 100;
inline constexpr int kThLow = 50;
inline constexpr float kRatioLoose = 0.9f;
inline constexpr float kRatioStrict = 0.75f;
// @}
// Chi-square 95% quantile, 1 degree of freedom: the epipolar-line test.
inline constexpr double kEpipolarChi2 = 3.84;
}  // namespace matching

// A map point's prediction in a frame, for a search by projection.
struct ProjectionQuery {
  // @{
  // Predicted pixel.
  float u = 0, v = 0;    // predicted undistorted pixel
  // @}
  float uRight = -1.f;   // predicted right coordinate; < 0 for none
  int octave = 0;        // predicted pyramid level
  float viewCos = 1.f;   // cosine between this view's ray and the point's mean viewing direction
  // The point's descriptor.
  OrbDescriptor descriptor;
  float windowStretch = 1.f;  // the window's widening by the camera's lens there (1: none)
};

namespace detail {
inline std::vector<std::uint8_t> takenMask(std::span<const std::uint8_t> taken, std::size_t n) {
  std::vector<std::uint8_t> mask(n, 0);
  std::copy_n(taken.begin(), std::min(n, taken.size()), mask.begin());
  return mask;
}
}  // namespace detail

// The two keypoints nearest to a query descriptor; best < 0 when no candidate was compared.
struct NearestTwo {
  // Index of the best keypoint, or −1.
  long best = -1;
  // @{
  // Distances of the best and second-best keypoints.
  int bestDistance = std::numeric_limits<int>::max();
  int secondDistance = std::numeric_limits<int>::max();
  // @}
  // @{
  // Levels of the best and second-best (−1 for none).
  int bestOctave = -1, secondOctave = -1;  // -1 for none
  // @}
  // Takes keypoint `index` (level `octave`) at distance d; a tie keeps the earlier one.
  void offer(int d, int octave, long index) {
    if (d < bestDistance) {
      secondDistance = bestDistance;
      secondOctave = bestOctave;
      bestDistance = d;
      bestOctave = octave;
      best = index;
    } else if (d < secondDistance) {
      secondDistance = d;
      secondOctave = octave;
    }
  }
};

// The nearest and second-nearest keypoints of `features` to `query` among `candidates`
// (keypoint indices, visited in order; ties keep the earlier one), leaving out those for which
// skip(index) holds.
template <class Candidates, class Skip, class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
NearestTwo nearestTwo(const FrameFeatures& features, const OrbDescriptor& query, const Candidates& candidates,
                      Skip&& skip, const Distance& distance = {}) {
  NearestTwo n;
  for (const auto candidate : candidates) {
    const auto i = static_cast<std::size_t>(candidate);
    if (skip(i)) continue;
    n.offer(distance(query, features.descriptors[i]), features.keypointsUn[i].octave, static_cast<long>(i));
  }
  return n;
}

// nearestTwo over the grid window FeatureGrid::featuresInArea(u, v, r, minLevel, maxLevel) would
// list, visited in the same order, without listing it.
template <class Skip, class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
NearestTwo nearestTwoInArea(const FrameFeatures& features, const OrbDescriptor& query, float u, float v, float r,
                            int minLevel, int maxLevel, Skip&& skip, const Distance& distance = {}) {
  NearestTwo n;
  features.grid.forEachInArea(u, v, r, minLevel, maxLevel, [&](int index, int octave) {
    const auto i = static_cast<std::size_t>(index);
    if (skip(i)) return;
    n.offer(distance(query, features.descriptors[i]), octave, static_cast<long>(i));
  });
  return n;
}

// Stereo check of a search window of radius r: a predicted and an observed right coordinate
// (each < 0 for none) that both exist and lie more than r apart.
inline bool rightCoordinateDisagrees(float predicted, float observed, float r) {
  return predicted >= 0.f && observed >= 0.f && std::abs(predicted - observed) > r;
}

// ORB-SLAM's SearchForTriangulation test for keypoint i1 of f1, whose epipolar line in image 2
// is `line`: the best of `candidates` (keypoint indices of f2, `skip` ones left out) by
// descriptor distance, at most kThLow with ties going to the later candidate (as ORB-SLAM),
// within χ² 3.84·σ² of the line, and, when neither keypoint has depth, away from the epipole
// (no parallax there). -1 when none qualifies.
template <class Candidates, class Skip, class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
long bestEpipolarPartner(const FrameFeatures& f1, std::size_t i1, const FrameFeatures& f2,
                         const Candidates& candidates, const Eigen::Vector3d& line,
                         const Eigen::Vector2d& epipole2, bool onlyStereo, Skip&& skip, const Distance& distance = {}) {
  const double lineNorm2 = line.x() * line.x() + line.y() * line.y();
  if (!(lineNorm2 > 0)) return -1;
  const bool stereo1 = f1.uRight[i1] >= 0.f;
  if (onlyStereo && !stereo1) return -1;
  int bestDist = matching::kThLow;
  long best = -1;
  for (const auto candidate : candidates) {
    const auto i2 = static_cast<std::size_t>(candidate);
    if (skip(i2)) continue;
    const bool stereo2 = f2.uRight[i2] >= 0.f;
    if (onlyStereo && !stereo2) continue;
    const int d = distance(f1.descriptors[i1], f2.descriptors[i2]);
    if (d > bestDist) continue;
    const Keypoint& k2 = f2.keypointsUn[i2];
    const auto level2 = static_cast<std::size_t>(k2.octave);
    if (!stereo1 && !stereo2) {
      const double ex = epipole2.x() - k2.u, ey = epipole2.y() - k2.v;
      if (ex * ex + ey * ey < 100 * f2.scales.scale[level2]) continue;
    }
    const double num = line.x() * k2.u + line.y() * k2.v + line.z();
    if (num * num / lineNorm2 < matching::kEpipolarChi2 * f2.scales.sigma2[level2]) {
      best = static_cast<long>(i2);
      bestDist = d;
    }
  }
  return best;
}

// matches[q] = keypoint index or -1; `taken` marks keypoints already matched (may be empty);
// a matched keypoint is taken for the later queries. Returns the number of matches.
template <class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
int searchByProjection(const FrameFeatures& frame, std::span<const ProjectionQuery> queries, float th,
                       float ratio, std::span<const std::uint8_t> taken, std::vector<int>& matches,
                       const Distance& distance = {}) {
  matches.assign(queries.size(), -1);
  std::vector<std::uint8_t> used = detail::takenMask(taken, frame.size());
  int count = 0;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const ProjectionQuery& query = queries[q];
    const int level = std::clamp(query.octave, 0, frame.scales.levels() - 1);
    // Viewing almost along the mean direction: appearance is reliable, search tighter.
    const float base = query.viewCos > 0.998f ? 2.5f : 4.f;
    const float r = base * th * frame.scales.scale[static_cast<std::size_t>(level)] * query.windowStretch;
    const NearestTwo n = nearestTwoInArea(
        frame, query.descriptor, query.u, query.v, r, level - 1, level,
        [&](std::size_t i) { return used[i] || rightCoordinateDisagrees(query.uRight, frame.uRight[i], r); }, distance);
    if (n.best < 0 || n.bestDistance > matching::kThHigh) continue;
    if (n.bestOctave == n.secondOctave &&
        static_cast<float>(n.bestDistance) > ratio * static_cast<float>(n.secondDistance))
      continue;
    matches[q] = static_cast<int>(n.best);
    used[static_cast<std::size_t>(n.best)] = 1;
    ++count;
  }
  return count;
}

// predictedInFrame2[i]: where keypoint i of frame 1 is expected in frame 2 (its previous
// match, or its own position). matches12[i] = keypoint of frame 2 or -1.
template <class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
int searchForInitialization(const FrameFeatures& f1, const FrameFeatures& f2,
                            std::span<const Eigen::Vector2f> predictedInFrame2, float windowSize, float ratio,
                            bool checkOrientation, std::vector<int>& matches12, const Distance& distance = {}) {
  matches12.assign(f1.size(), -1);
  std::vector<int> matches21(f2.size(), -1), distance21(f2.size(), std::numeric_limits<int>::max());
  std::vector<int> candidates;
  RotationHistogram histogram;
  for (std::size_t i1 = 0; i1 < f1.size(); ++i1) {
    const Keypoint& k1 = f1.keypointsUn[i1];
    if (k1.octave > 0) continue;  // ORB-SLAM initialises from the finest level only
    const Eigen::Vector2f& p = predictedInFrame2[i1];
    f2.grid.featuresInArea(p.x(), p.y(), windowSize, k1.octave, k1.octave, candidates);
    int best = std::numeric_limits<int>::max(), second = best, bestIdx = -1;
    for (int i2 : candidates) {
      const int d = distance(f1.descriptors[i1], f2.descriptors[static_cast<std::size_t>(i2)]);
      if (distance21[static_cast<std::size_t>(i2)] <= d) continue;  // taken by an equal or better match
      if (d < best) {
        second = best;
        best = d;
        bestIdx = i2;
      } else if (d < second) {
        second = d;
      }
    }
    if (bestIdx < 0 || best > matching::kThLow) continue;
    const auto b = static_cast<std::size_t>(bestIdx);
    if (static_cast<float>(best) >= ratio * static_cast<float>(second)) continue;
    if (matches21[b] >= 0) matches12[static_cast<std::size_t>(matches21[b])] = -1;  // displaced
    matches12[i1] = bestIdx;
    matches21[b] = static_cast<int>(i1);
    distance21[b] = best;
  }
  if (checkOrientation) {
    for (std::size_t i1 = 0; i1 < f1.size(); ++i1)
      if (matches12[i1] >= 0)
        histogram.add(f1.keypointsUn[i1].angle - f2.keypointsUn[static_cast<std::size_t>(matches12[i1])].angle,
                      static_cast<int>(i1));
    std::vector<int> drop;
    histogram.rejected(drop);
    for (int i1 : drop) matches12[static_cast<std::size_t>(i1)] = -1;
  }
  return static_cast<int>(std::count_if(matches12.begin(), matches12.end(), [](int m) { return m >= 0; }));
}

// F21 such that x2^T F21 x1 = 0 for pixels of a rigid scene: K2^-T [t21]x R21 K1^-1, where
// X2 = R21 X1 + t21.
inline Eigen::Matrix3d fundamentalFromPose(const Eigen::Matrix3d& R21, const Eigen::Vector3d& t21,
                                           const Eigen::Matrix3d& K1, const Eigen::Matrix3d& K2) {
  Eigen::Matrix3d tx;
  tx << 0, -t21.z(), t21.y(), t21.z(), 0, -t21.x(), -t21.y(), t21.x(), 0;
  return K2.inverse().transpose() * tx * R21 * K1.inverse();
}

}  // namespace orbis
