// orbis/features/matcher.hpp — descriptor matching with geometric priors (ORB-SLAM's searches).
//
// Contract: every search takes plain query arrays (no map objects) and a FrameFeatures, and
// returns matches as indices; nothing throws, and with a reused output vector nothing allocates
// after warm-up except the grid query buffer. Thresholds are ORB-SLAM's named constants:
// kThHigh = 100 and kThLow = 50 (Hamming bits), nearest/second-nearest ratios kRatioLoose =
// 0.9 and kRatioStrict = 0.75 (callers pass the one their stage uses), and the rotation
// histogram of rotation_histogram.hpp. Every search is a template over the distance policy
// (HammingDistance by default) so the inner loop is inlined.
//  - searchByProjection: map points predicted in the frame (pixel, right coordinate, octave,
//    viewing-angle cosine); window radius 2.5 px (4 px when the viewing angle differs by more
//    than ~3.6 degrees from the mean) x th x the octave's scale, octaves [o-1, o], best/second
//    ratio when both lie on one octave, stereo coordinate check; one query per keypoint.
//  - searchFrameToFrame: the last frame's tracked keypoints projected with a motion prior;
//    radius th x scale of the last octave; when the camera moved forward (backward) along its
//    axis by more than the baseline, only octaves >= (<=) the last one, else within one;
//    best distance <= kThHigh, optional rotation check.
//  - searchForInitialization: monocular initialisation; level-0 keypoints of frame 1 searched in a
//    square window around their previous match in frame 2, kThLow, ratio, one-to-one, rotation.
//  - searchForTriangulation: unmatched keypoints of two views along the epipolar line
//    (x2^T F21 x1 = 0): squared distance to the line < 3.84 sigma^2 of the octave in view 2,
//    kThLow, not near the epipole for two monocular keypoints, optional grouping (e.g. the
//    vocabulary node of each keypoint, as ORB-SLAM restricts candidates), rotation check.
//  - bruteForceMatch: exhaustive nearest neighbour with optional cross-check.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <ranges>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/features/rotation_histogram.hpp"

namespace orbis {

namespace matching {
inline constexpr int kThHigh = 100;
inline constexpr int kThLow = 50;
inline constexpr float kRatioLoose = 0.9f;
inline constexpr float kRatioStrict = 0.75f;
// Chi-square 95% quantile, 1 degree of freedom: the epipolar-line test.
inline constexpr double kEpipolarChi2 = 3.84;
}  // namespace matching

struct ProjectionQuery {
  float u = 0, v = 0;    // predicted undistorted pixel
  float uRight = -1.f;   // predicted right coordinate; < 0 for none
  int octave = 0;        // predicted pyramid level
  float viewCos = 1.f;   // cosine between this view's ray and the point's mean viewing direction
  OrbDescriptor descriptor;
};

struct TrackedQuery {
  float u = 0, v = 0;   // projection into the current frame
  float uRight = -1.f;  // projected right coordinate; < 0 for none
  int lastOctave = 0;   // octave of the keypoint in the last frame
  float lastAngle = 0;  // its orientation, degrees
  OrbDescriptor descriptor;
};

struct DescriptorMatch {
  int query = -1, train = -1, distance = 0;
};

namespace detail {
inline std::vector<std::uint8_t> takenMask(std::span<const std::uint8_t> taken, std::size_t n) {
  std::vector<std::uint8_t> mask(n, 0);
  std::copy_n(taken.begin(), std::min(n, taken.size()), mask.begin());
  return mask;
}

// ORB-SLAM's SearchForTriangulation test for keypoint i1 of f1, whose epipolar line in image 2
// is `line`: the best of `candidates` (keypoint indices of f2, `skip` ones left out) by
// descriptor distance, at most kThLow with ties going to the later candidate (as ORB-SLAM),
// within χ² 3.84·σ² of the line, and, when neither keypoint has depth, away from the epipole
// (no parallax there). -1 when none qualifies.
template <class Candidates, class Skip, class Distance>
long bestEpipolarPartner(const FrameFeatures& f1, std::size_t i1, const FrameFeatures& f2,
                         const Candidates& candidates, const Eigen::Vector3d& line,
                         const Eigen::Vector2d& epipole2, bool onlyStereo, Skip&& skip, const Distance& distance) {
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

}  // namespace detail

// matches[q] = keypoint index or -1; `taken` marks keypoints already matched (may be empty).
// Returns the number of matches.
template <class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
int searchByProjection(const FrameFeatures& frame, std::span<const ProjectionQuery> queries, float th,
                       float ratio, std::span<const std::uint8_t> taken, std::vector<int>& matches,
                       const Distance& distance = {}) {
  matches.assign(queries.size(), -1);
  std::vector<std::uint8_t> used = detail::takenMask(taken, frame.size());
  std::vector<int> candidates;
  int count = 0;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const ProjectionQuery& query = queries[q];
    const int level = std::clamp(query.octave, 0, frame.scales.levels() - 1);
    // Viewing almost along the mean direction: appearance is reliable, search tighter.
    const float base = query.viewCos > 0.998f ? 2.5f : 4.f;
    const float r = base * th * frame.scales.scale[static_cast<std::size_t>(level)];
    frame.grid.featuresInArea(query.u, query.v, r, level - 1, level, candidates);
    int best = std::numeric_limits<int>::max(), second = best, bestLevel = -1, secondLevel = -1, bestIdx = -1;
    for (int idx : candidates) {
      const auto i = static_cast<std::size_t>(idx);
      if (used[i]) continue;
      if (query.uRight >= 0.f && frame.uRight[i] > 0.f && std::abs(query.uRight - frame.uRight[i]) > r) continue;
      const int d = distance(query.descriptor, frame.descriptors[i]);
      if (d < best) {
        second = best;
        secondLevel = bestLevel;
        best = d;
        bestLevel = frame.keypointsUn[i].octave;
        bestIdx = idx;
      } else if (d < second) {
        second = d;
        secondLevel = frame.keypointsUn[i].octave;
      }
    }
    if (bestIdx < 0 || best > matching::kThHigh) continue;
    if (bestLevel == secondLevel && static_cast<float>(best) > ratio * static_cast<float>(second)) continue;
    matches[q] = bestIdx;
    used[static_cast<std::size_t>(bestIdx)] = 1;
    ++count;
  }
  return count;
}

// forward/backward: the camera advanced/retreated along its axis by more than the baseline
// (stereo/RGB-D only; pass false for monocular). matches[q] = keypoint index or -1.
template <class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
int searchFrameToFrame(const FrameFeatures& current, std::span<const TrackedQuery> queries, float th,
                       bool forward, bool backward, bool checkOrientation,
                       std::span<const std::uint8_t> taken, std::vector<int>& matches,
                       const Distance& distance = {}) {
  matches.assign(queries.size(), -1);
  std::vector<std::uint8_t> used = detail::takenMask(taken, current.size());
  std::vector<int> candidates;
  RotationHistogram histogram;
  const int levels = current.scales.levels();
  int count = 0;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const TrackedQuery& query = queries[q];
    const int last = std::clamp(query.lastOctave, 0, levels - 1);
    const float r = th * current.scales.scale[static_cast<std::size_t>(last)];
    // Moving forward, a point looks bigger: it is found at a finer-scale level no lower than
    // before; moving backward, at one no higher.
    if (forward)
      current.grid.featuresInArea(query.u, query.v, r, last, -1, candidates);
    else if (backward)
      current.grid.featuresInArea(query.u, query.v, r, 0, last, candidates);
    else
      current.grid.featuresInArea(query.u, query.v, r, std::max(0, last - 1), last + 1, candidates);
    int best = std::numeric_limits<int>::max(), bestIdx = -1;
    for (int idx : candidates) {
      const auto i = static_cast<std::size_t>(idx);
      if (used[i]) continue;
      if (query.uRight >= 0.f && current.uRight[i] > 0.f && std::abs(query.uRight - current.uRight[i]) > r) continue;
      const int d = distance(query.descriptor, current.descriptors[i]);
      if (d < best) {
        best = d;
        bestIdx = idx;
      }
    }
    if (bestIdx < 0 || best > matching::kThHigh) continue;
    matches[q] = bestIdx;
    used[static_cast<std::size_t>(bestIdx)] = 1;
    ++count;
    if (checkOrientation)
      histogram.add(query.lastAngle - current.keypointsUn[static_cast<std::size_t>(bestIdx)].angle, static_cast<int>(q));
  }
  if (checkOrientation) {
    std::vector<int> drop;
    histogram.rejected(drop);
    for (int q : drop) {
      matches[static_cast<std::size_t>(q)] = -1;
      --count;
    }
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

struct EpipolarSearchOptions {
  bool onlyStereo = false;        // both keypoints must have a stereo coordinate
  bool checkOrientation = true;
  std::span<const std::uint8_t> taken1, taken2;     // already matched keypoints (may be empty)
  std::span<const std::uint32_t> group1, group2;    // candidates only within one group (may be empty)
};

// Pairs (i1, i2) of keypoints consistent with F21; epipole2 is camera 1's centre in image 2.
template <class Distance = HammingDistance>
  requires DescriptorDistance<Distance, OrbDescriptor>
int searchForTriangulation(const FrameFeatures& f1, const FrameFeatures& f2, const Eigen::Matrix3d& F21d,
                           const Eigen::Vector2f& epipole2, const EpipolarSearchOptions& options,
                           std::vector<std::pair<int, int>>& pairs, const Distance& distance = {}) {
  pairs.clear();
  const std::vector<std::uint8_t> taken1 = detail::takenMask(options.taken1, f1.size());
  std::vector<std::uint8_t> taken2 = detail::takenMask(options.taken2, f2.size());
  const bool grouped = !options.group1.empty() && !options.group2.empty();
  const Eigen::Vector2d epipole = epipole2.cast<double>();
  RotationHistogram histogram;
  for (std::size_t i1 = 0; i1 < f1.size(); ++i1) {
    if (taken1[i1]) continue;
    const Keypoint& k1 = f1.keypointsUn[i1];
    // The epipolar line of k1 in image 2; every keypoint of f2 is a candidate.
    const Eigen::Vector3d line = F21d * Eigen::Vector3d(k1.u, k1.v, 1.0);
    const auto skip = [&](std::size_t i2) { return taken2[i2] || (grouped && options.group1[i1] != options.group2[i2]); };
    const long best = detail::bestEpipolarPartner(f1, i1, f2, std::views::iota(std::size_t{0}, f2.size()), line,
                                                  epipole, options.onlyStereo, skip, distance);
    const int bestIdx = static_cast<int>(best);
    if (bestIdx < 0) continue;
    taken2[static_cast<std::size_t>(bestIdx)] = 1;
    if (options.checkOrientation)
      histogram.add(k1.angle - f2.keypointsUn[static_cast<std::size_t>(bestIdx)].angle, static_cast<int>(pairs.size()));
    pairs.emplace_back(static_cast<int>(i1), bestIdx);
  }
  if (options.checkOrientation) {
    std::vector<int> drop;
    histogram.rejected(drop);
    std::vector<std::uint8_t> dropped(pairs.size(), 0);
    for (int p : drop) dropped[static_cast<std::size_t>(p)] = 1;
    std::size_t kept = 0;
    for (std::size_t p = 0; p < pairs.size(); ++p)
      if (!dropped[p]) pairs[kept++] = pairs[p];
    pairs.resize(kept);
  }
  return static_cast<int>(pairs.size());
}

// Exhaustive nearest neighbour of each query among `train`, at most maxDistance; with
// crossCheck, kept only when the query is also the train descriptor's nearest neighbour.
template <class Distance = HammingDistance>
  requires DescriptorDistance<Distance, typename Distance::Descriptor>
std::vector<DescriptorMatch> bruteForceMatch(std::span<const typename Distance::Descriptor> query,
                                             std::span<const typename Distance::Descriptor> train,
                                             int maxDistance = matching::kThHigh, bool crossCheck = true,
                                             const Distance& distance = {}) {
  std::vector<DescriptorMatch> forward(query.size());
  std::vector<int> backwardBest(train.size(), std::numeric_limits<int>::max()), backwardIdx(train.size(), -1);
  for (std::size_t q = 0; q < query.size(); ++q) {
    DescriptorMatch m{static_cast<int>(q), -1, std::numeric_limits<int>::max()};
    for (std::size_t t = 0; t < train.size(); ++t) {
      const int d = distance(query[q], train[t]);
      if (d < m.distance) {
        m.distance = d;
        m.train = static_cast<int>(t);
      }
      // First query wins ties, as the forward direction's first train does.
      if (d < backwardBest[t]) {
        backwardBest[t] = d;
        backwardIdx[t] = static_cast<int>(q);
      }
    }
    forward[q] = m;
  }
  std::vector<DescriptorMatch> out;
  for (const DescriptorMatch& m : forward) {
    if (m.train < 0 || m.distance > maxDistance) continue;
    if (crossCheck && backwardIdx[static_cast<std::size_t>(m.train)] != m.query) continue;
    out.push_back(m);
  }
  return out;
}

}  // namespace orbis
