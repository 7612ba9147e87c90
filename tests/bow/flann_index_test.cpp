#include "orbis/bow/flann_index.hpp"

#include <gtest/gtest.h>

#include "bow/bow_test_util.hpp"

namespace orbis::bow {
namespace {

struct MatchSet {
  std::vector<OrbDescriptor> indexed, queries;
  std::vector<int> truth;  // index each query was copied from
};

MatchSet noisyCopies(int indexedCount, int queryCount, int flips) {
  detail::SplitMix64 rng{42};
  MatchSet s;
  for (int i = 0; i < indexedCount; ++i) s.indexed.push_back(test::randomDescriptor(rng));
  for (int i = 0; i < queryCount; ++i) {
    const auto j = static_cast<int>(rng.below(static_cast<std::uint64_t>(indexedCount)));
    s.queries.push_back(test::flipBits(s.indexed[static_cast<std::size_t>(j)], flips, rng));
    s.truth.push_back(j);
  }
  return s;
}

TEST(BinaryDescriptorIndex, BruteForceFindsTheExactNearest) {
  const MatchSet s = noisyCopies(500, 50, 20);
  const auto m = bruteForceNearest(s.indexed, s.queries);
  for (std::size_t i = 0; i < m.size(); ++i) {
    EXPECT_EQ(m[i].index, s.truth[i]);  // 20 flips from a random descriptor: far closer than any other
    for (const OrbDescriptor& d : s.indexed) EXPECT_LE(m[i].distance, hammingDistance(s.queries[i], d));
  }
}

TEST(BinaryDescriptorIndex, HierarchicalClusteringIsDeterministicAndFindsCloseMatches) {
  const MatchSet s = noisyCopies(5000, 300, 15);
  BinaryDescriptorIndex a(s.indexed), b(s.indexed);
  EXPECT_EQ(a.size(), 5000u);
  const auto ma = a.nearest(s.queries), mb = b.nearest(s.queries);
  int found = 0;
  for (std::size_t i = 0; i < ma.size(); ++i) {
    EXPECT_EQ(ma[i].index, mb[i].index);
    if (ma[i].index == s.truth[i]) ++found;
    if (ma[i].index >= 0) EXPECT_EQ(ma[i].distance, hammingDistance(s.queries[i], s.indexed[static_cast<std::size_t>(ma[i].index)]));
  }
  EXPECT_GT(found, 270) << "recall of clearly matching descriptors";
}

TEST(BinaryDescriptorIndex, LshFindsCloseMatches) {
  const MatchSet s = noisyCopies(5000, 300, 10);
  BinaryIndexParams p;
  p.algorithm = BinaryIndexParams::Algorithm::Lsh;
  BinaryDescriptorIndex lsh(s.indexed, p);
  const auto m = lsh.nearest(s.queries);
  int found = 0;
  for (std::size_t i = 0; i < m.size(); ++i) found += m[i].index == s.truth[i] ? 1 : 0;
  EXPECT_GT(found, 240);
}

TEST(BinaryDescriptorIndex, EmptyIndexFindsNothing) {
  BinaryDescriptorIndex empty({});
  detail::SplitMix64 rng{1};
  const auto m = empty.nearest(std::vector<OrbDescriptor>{test::randomDescriptor(rng)});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].index, -1);
}

}  // namespace
}  // namespace orbis::bow
