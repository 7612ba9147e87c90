// The generic searches on two views of a textured plane with known camera motion
// (features/plane_views.hpp), checked for finding right matches and for rejecting wrong ones.
// The map-level searches built on the same kernels are tested in tests/map/.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "features/plane_views.hpp"
#include "orbis/features/matcher.hpp"

namespace orbis {
namespace {

using test::PlaneViews;
using test::planeViews;
using test::Tally;

// The kernel under every search: the two nearest candidates, visited in the order given.
TEST(Matcher, NearestTwoKeepsTheEarlierOfEqualCandidatesAndHonoursSkip) {
  const auto withBits = [](int bits) {
    OrbDescriptor d;
    for (int b = 0; b < bits; ++b) d.words[static_cast<std::size_t>(b / 64)] |= std::uint64_t{1} << (b % 64);
    return d;
  };
  FrameFeatures f;
  const int bits[] = {9, 3, 3, 7};  // distances to an all-zero query
  for (int i = 0; i < 4; ++i) {
    f.descriptors.push_back(withBits(bits[i]));
    f.keypointsUn.push_back(Keypoint{0.f, 0.f, 0.f, 0.f, i});
  }
  const OrbDescriptor query;
  const std::vector<int> all{0, 1, 2, 3};
  const NearestTwo n = nearestTwo(f, query, all, [](std::size_t) { return false; });
  EXPECT_EQ(n.best, 1);
  EXPECT_EQ(n.bestDistance, 3);
  EXPECT_EQ(n.secondDistance, 3);
  EXPECT_EQ(n.bestOctave, 1);
  EXPECT_EQ(n.secondOctave, 2);
  const NearestTwo skipped = nearestTwo(f, query, all, [](std::size_t i) { return i == 1 || i == 2; });
  EXPECT_EQ(skipped.best, 3);
  EXPECT_EQ(skipped.bestDistance, 7);
  EXPECT_EQ(skipped.secondDistance, 9);
  EXPECT_LT(nearestTwo(f, query, std::vector<int>{}, [](std::size_t) { return false; }).best, 0);
}

TEST(Matcher, SearchByProjectionFindsTrueAndRejectsForeignDescriptors) {
  const PlaneViews s = planeViews(4.0, {0.08, -0.03, 0.05}, 31);
  std::vector<ProjectionQuery> queries;
  for (const Keypoint& k : s.f1.keypointsUn) {
    const Eigen::Vector2d p = s.inView2(k);
    queries.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), -1.f, k.octave, 1.f, {}});
  }
  for (std::size_t i = 0; i < queries.size(); ++i) queries[i].descriptor = s.f1.descriptors[i];
  std::vector<int> matches;
  const int n = searchByProjection(s.f2, std::span<const ProjectionQuery>(queries), 1.f, matching::kRatioStrict, {}, matches);
  Tally t;
  for (std::size_t q = 0; q < matches.size(); ++q)
    if (matches[q] >= 0) {
      ++t.matched;
      t.correct += s.correct(static_cast<int>(q), matches[q], 2.5 * s.f1.scales.scale[static_cast<std::size_t>(s.f1.keypointsUn[q].octave)]);
    }
  EXPECT_EQ(n, t.matched);
  std::printf("[ matcher  ] by projection: %d of %zu queries matched, %d correct\n", t.matched, queries.size(), t.correct);
  EXPECT_GT(t.matched, static_cast<int>(queries.size()) / 3);
  EXPECT_GE(t.correct, t.matched * 95 / 100);
  // One keypoint per query at most.
  std::vector<int> used;
  for (int m : matches)
    if (m >= 0) used.push_back(m);
  std::sort(used.begin(), used.end());
  EXPECT_EQ(std::adjacent_find(used.begin(), used.end()), used.end());

  // The descriptors of other keypoints (a fixed shuffle) at the same predictions: mostly
  // rejected. Unrelated ORB descriptors are correlated enough that kThHigh (100 of 256 bits)
  // lets some through when a window holds a single candidate, as in ORB-SLAM.
  std::vector<ProjectionQuery> foreign = queries;
  std::mt19937 rng(5);
  std::vector<std::size_t> perm(queries.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  for (std::size_t i = 0; i < foreign.size(); ++i) foreign[i].descriptor = queries[perm[i]].descriptor;
  const int wrong = searchByProjection(s.f2, std::span<const ProjectionQuery>(foreign), 1.f, matching::kRatioStrict, {}, matches);
  std::printf("[ matcher  ] by projection with foreign descriptors: %d of %zu matched\n", wrong, queries.size());
  EXPECT_LT(wrong, t.correct / 2);

  // Keypoints marked as taken are never returned.
  std::vector<std::uint8_t> taken(s.f2.size(), 1);
  EXPECT_EQ(searchByProjection(s.f2, std::span<const ProjectionQuery>(queries), 1.f, 0.75f, taken, matches), 0);
}

TEST(Matcher, InitializationWindowSearchAndRotationCheck) {
  const PlaneViews s = planeViews(25.0, {0.05, 0.02, 0.0}, 33);  // a 25-degree roll
  std::vector<Eigen::Vector2f> predicted;
  for (const Keypoint& k : s.f1.keypointsUn) predicted.emplace_back(k.u, k.v);  // no prior: own position
  std::vector<int> m12;
  const int n = searchForInitialization(s.f1, s.f2, std::span<const Eigen::Vector2f>(predicted), 100.f,
                                        matching::kRatioLoose, true, m12);
  Tally t;
  for (std::size_t i = 0; i < m12.size(); ++i)
    if (m12[i] >= 0) {
      ++t.matched;
      t.correct += s.correct(static_cast<int>(i), m12[i], 3.0);
      EXPECT_EQ(s.f1.keypointsUn[i].octave, 0);
    }
  std::printf("[ matcher  ] initialisation window: %d matched, %d correct\n", t.matched, t.correct);
  EXPECT_EQ(n, t.matched);
  EXPECT_GT(t.matched, 60);
  EXPECT_GE(t.correct, t.matched * 95 / 100);
}

TEST(Matcher, RotationHistogramRejectsInconsistentRotations) {
  RotationHistogram h;
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.f, 2.f);
  std::uniform_real_distribution<float> any(0.f, 360.f);
  for (int i = 0; i < 200; ++i) h.add(-30.f + noise(rng), i);  // consistent: about 330 degrees
  for (int i = 200; i < 240; ++i) h.add(any(rng), i);         // inconsistent
  std::vector<int> out;
  h.rejected(out);
  const auto consistentRejected = std::count_if(out.begin(), out.end(), [](int i) { return i < 200; });
  const auto inconsistentRejected = std::count_if(out.begin(), out.end(), [](int i) { return i >= 200; });
  EXPECT_LT(consistentRejected, 3);
  EXPECT_GT(inconsistentRejected, 30);
}

}  // namespace
}  // namespace orbis
