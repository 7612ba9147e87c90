#include "orbis/bow/vocabulary.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>

#include "bow/bow_test_util.hpp"

namespace orbis::bow {
namespace {

bool sameBytes(const OrbVocabulary& a, const OrbVocabulary& b) {
  const auto x = a.blob().bytes(), y = b.blob().bytes();
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size()) == 0;
}

TEST(Vocabulary, TrainingIsDeterministicAndIndependentOfThreadCount) {
  const OrbVocabulary a = test::trainSmall(7, 1);
  const OrbVocabulary b = test::trainSmall(7, 1);
  const OrbVocabulary c = test::trainSmall(7, 2);
  const OrbVocabulary d = test::trainSmall(7, 3);
  EXPECT_TRUE(sameBytes(a, b));
  EXPECT_TRUE(sameBytes(a, c));
  EXPECT_TRUE(sameBytes(a, d));
  EXPECT_FALSE(sameBytes(a, test::trainSmall(8, 1))) << "the seed must matter";
}

TEST(Vocabulary, EmptyVocabularyTransformsToEmptyVectors) {
  const OrbVocabulary empty;
  EXPECT_TRUE(empty.empty());
  const auto images = test::syntheticImages(3, 1, 10, 10, 2);
  EXPECT_TRUE(empty.transform(images[0]).empty());
  BowVector bow = BowVector::fromUnsorted({{1, 1.0}}, true);
  FeatureVector fv;
  empty.transform(images[0], bow, fv, 2);
  EXPECT_TRUE(bow.empty());
  EXPECT_TRUE(fv.empty());
}

TEST(Vocabulary, TreeShapeRespectsKAndL) {
  const OrbVocabulary v = test::trainSmall(7, 2, 5, 3);
  EXPECT_EQ(v.branching(), 5u);
  EXPECT_EQ(v.depth(), 3u);
  ASSERT_GT(v.wordCount(), 25u);  // 300 prototypes must fill more than two levels
  EXPECT_LE(v.wordCount(), 125u);
  std::size_t leaves = 0;
  for (NodeId n = 0; n < v.nodeCount(); ++n) {
    const NodeRecord& r = v.node(n);
    EXPECT_LE(r.childCount, 5u);
    int depth = 0;
    for (NodeId p = n; p != 0; p = v.node(p).parent) ++depth;
    EXPECT_LE(depth, 3);
    if (r.childCount == 0) {
      ++leaves;
      EXPECT_EQ(v.wordNode(r.wordId), n);
    }
  }
  EXPECT_EQ(leaves, v.wordCount());
}

TEST(Vocabulary, TransformDescendsToTheNearestChildAtEveryLevel) {
  const OrbVocabulary v = test::trainSmall();
  detail::SplitMix64 rng{99};
  for (int trial = 0; trial < 300; ++trial) {
    const OrbDescriptor d = test::randomDescriptor(rng);
    const WordId w = v.wordOf(d);
    ASSERT_LT(w, v.wordCount());
    // Walk back up from the word: at every level the node taken must be a nearest sibling.
    for (NodeId n = v.wordNode(w); n != 0; n = v.node(n).parent) {
      const NodeRecord& parent = v.node(v.node(n).parent);
      int best = 1000;
      for (NodeId c = parent.firstChild; c < parent.firstChild + parent.childCount; ++c)
        best = std::min(best, hammingDistance(d, v.nodeDescriptor(c)));
      EXPECT_EQ(hammingDistance(d, v.nodeDescriptor(n)), best);
    }
  }
}

TEST(Vocabulary, NoisyCopiesOfATrainingDescriptorUsuallyShareItsWord) {
  const auto images = test::syntheticImages(11, 40, 120, 300, 12);
  const OrbVocabulary v = test::trainSmall();
  detail::SplitMix64 rng{5};
  int same = 0, total = 0;
  for (const auto& image : images)
    for (std::size_t i = 0; i < image.size(); i += 10, ++total)
      same += v.wordOf(image[i]) == v.wordOf(test::flipBits(image[i], 3, rng)) ? 1 : 0;
  EXPECT_GT(same, total * 8 / 10) << same << " of " << total;
}

TEST(Vocabulary, BowVectorIsSortedNormalisedAndWeighted) {
  const OrbVocabulary v = test::trainSmall();
  const auto images = test::syntheticImages(3, 2, 200, 300, 12);
  const BowVector bow = v.transform(images[0]);
  ASSERT_FALSE(bow.empty());
  double sum = 0;
  for (std::size_t i = 0; i < bow.size(); ++i) {
    sum += bow[i].weight;
    EXPECT_GT(bow[i].weight, 0);
    if (i > 0) EXPECT_LT(bow[i - 1].word, bow[i].word);
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  // TF-IDF: a word's weight is its idf times its count, before normalisation.
  std::vector<double> raw(v.wordCount(), 0.0);
  for (const OrbDescriptor& d : images[0]) raw[v.wordOf(d)] += v.wordWeight(v.wordOf(d));
  const double total = std::accumulate(raw.begin(), raw.end(), 0.0);
  for (const WordEntry& e : bow) EXPECT_NEAR(e.weight, raw[e.word] / total, 1e-9);
}

TEST(Vocabulary, ScoreIsOneForSelfZeroForDisjointAndSymmetric) {
  const OrbVocabulary v = test::trainSmall();
  const auto images = test::syntheticImages(21, 6, 150, 300, 12);
  for (const auto& a : images) {
    const BowVector ba = v.transform(a);
    EXPECT_NEAR(v.score(ba, ba), 1.0, 1e-12);
    for (const auto& b : images) {
      const BowVector bb = v.transform(b);
      const double s = v.score(ba, bb);
      EXPECT_GE(s, 0.0);
      EXPECT_LE(s, 1.0 + 1e-12);
      EXPECT_DOUBLE_EQ(s, v.score(bb, ba));
      // Definition check: 1 - |a - b|_1 / 2 over the union of words.
      double diff = 0;
      for (WordId w = 0; w < v.wordCount(); ++w) diff += std::abs(ba.weightOf(w) - bb.weightOf(w));
      EXPECT_NEAR(s, 1.0 - diff / 2, 1e-9);
    }
  }
  const BowVector x = BowVector::fromUnsorted({{1, 0.5}, {3, 0.5}}, true);
  const BowVector y = BowVector::fromUnsorted({{2, 0.25}, {4, 0.75}}, true);
  EXPECT_EQ(l1Score(x, y), 0.0);
  EXPECT_EQ(commonWords(x, y), 0u);
}

TEST(Vocabulary, FeatureVectorGroupsFeaturesByAncestorNode) {
  const OrbVocabulary v = test::trainSmall(7, 1, 5, 3);
  const auto images = test::syntheticImages(4, 1, 300, 300, 12);
  for (int levelsUp : {0, 1, 2, 5}) {
    BowVector bow;
    FeatureVector fv;
    v.transform(images[0], bow, fv, levelsUp);
    EXPECT_EQ(bow, v.transform(images[0]));
    std::size_t features = 0;
    for (std::size_t g = 0; g < fv.size(); ++g) {
      if (g > 0) EXPECT_LT(fv.node(g - 1), fv.node(g));
      for (std::uint32_t f : fv.featuresOf(g)) {
        ++features;
        // The group node is the ancestor of the feature's word at depth L - levelsUp (or the leaf).
        NodeId n = v.wordNode(v.wordOf(images[0][f]));
        std::vector<NodeId> path;
        for (NodeId p = n; p != 0; p = v.node(p).parent) path.insert(path.begin(), p);
        const int want = std::max(0, 3 - levelsUp);
        const NodeId expected = want == 0 ? 0 : path[static_cast<std::size_t>(std::min<int>(want, static_cast<int>(path.size())) - 1)];
        EXPECT_EQ(fv.node(g), expected);
      }
    }
    EXPECT_EQ(features, fv.featureCount());
    EXPECT_GT(features, 200u);
  }
}

}  // namespace
}  // namespace orbis::bow
