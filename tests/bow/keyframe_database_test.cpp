#include "orbis/bow/keyframe_database.hpp"

#include <gtest/gtest.h>

#include <map>
#include <vector>

namespace orbis::bow {
namespace {

// Words `words` at weight `w` each, plus `extra` words at weight `extraWeight`.
BowVector bowOf(std::vector<WordId> words, double w, std::vector<WordId> extra = {}, double extraWeight = 0.1) {
  std::vector<WordEntry> e;
  for (WordId x : words) e.push_back({x, w});
  for (WordId x : extra) e.push_back({x, extraWeight});
  return BowVector::fromUnsorted(std::move(e), true);
}
std::vector<WordId> range(WordId a, WordId b) {  // [a, b]
  std::vector<WordId> r;
  for (WordId x = a; x <= b; ++x) r.push_back(x);
  return r;
}

struct ToyGraph {
  std::map<KeyframeId, std::vector<KeyframeId>> connected;  // best first
  std::vector<KeyframeId> connectedKeyframes(KeyframeId id) const {
    auto it = connected.find(id);
    return it == connected.end() ? std::vector<KeyframeId>{} : it->second;
  }
  std::vector<KeyframeId> bestCovisibleKeyframes(KeyframeId id, std::size_t n) const {
    auto all = connectedKeyframes(id);
    if (all.size() > n) all.resize(n);
    return all;
  }
};
static_assert(CovisibilityGraph<ToyGraph>);

// Query Q = words 0..9 at 0.1. Scores against Q (L1, = sum of shared minima):
//   K1 0.9 (9 common), K2 0.8 (8), K3 0.8 (8), K4 0.4 (8 common at half weight), K5 0.5 (5),
//   K6 0.9 (9, no covisibles), C=50 0.7 (7).
// Covisibility: K1-{K2,K3,K4,K5}, K2-{K1,K3}, K3-{K1,K2}, K4-{K1}.
struct Scene {
  KeyframeDatabase db;
  ToyGraph graph;
  BowVector query = bowOf(range(0, 9), 0.1);
  Scene() {
    db.add(1, bowOf(range(0, 8), 0.1, {30}));
    db.add(2, bowOf(range(0, 7), 0.1, {31, 32}));
    db.add(3, bowOf(range(1, 8), 0.1, {33, 34}));
    db.add(4, bowOf(range(0, 7), 0.05, {35, 36}, 0.3));
    db.add(5, bowOf(range(0, 4), 0.1, range(40, 44)));
    db.add(6, bowOf(range(0, 8), 0.1, {45}));
    db.add(50, bowOf(range(0, 6), 0.1, {20, 21, 22}));
    graph.connected = {{1, {2, 3, 4, 5}}, {2, {1, 3}}, {3, {1, 2}}, {4, {1}}, {5, {1}}};
  }
};

TEST(KeyframeDatabase, PlainQueryRanksByScore) {
  Scene s;
  const auto top = s.db.query(s.query, 3, [](KeyframeId) { return true; });
  ASSERT_EQ(top.size(), 3u);
  EXPECT_EQ(top[0].keyframe, 1u);  // 0.9 tie with K6: lower id first
  EXPECT_EQ(top[1].keyframe, 6u);
  EXPECT_NEAR(top[0].score, 0.9, 1e-12);
  EXPECT_EQ(top[2].keyframe, 2u);
  const auto filtered = s.db.query(s.query, 10, [](KeyframeId id) { return id != 1 && id != 6; });
  ASSERT_EQ(filtered.size(), 5u);
  EXPECT_EQ(filtered[0].keyframe, 2u);
  EXPECT_EQ(filtered.back().keyframe, 4u);
  EXPECT_NEAR(filtered.back().score, 0.4, 1e-12);
}

TEST(KeyframeDatabase, RelocalisationAccumulatesOverCovisibilityGroups) {
  Scene s;
  // Scored (common > 0.8 x 9): K1 K2 K3 K4 K6. Groups: K1 0.9+0.8+0.8+0.4 = 2.9 (best K1),
  // K2 2.5 -> K1, K3 2.5 -> K1, K4 1.3 -> K1, K6 0.9. Kept: > 0.75 x 2.9; one entry per keyframe.
  const auto c = s.db.detectRelocalisationCandidates(s.query, s.graph);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].keyframe, 1u);
  EXPECT_NEAR(c[0].accumulatedScore, 2.9, 1e-12);
  EXPECT_NEAR(c[0].score, 0.9, 1e-12);
}

TEST(KeyframeDatabase, LoopCandidatesExcludeConnectedAndUseTheirMinimumScore) {
  Scene s;
  s.graph.connected[100] = {50};  // min score 0.7: K4 (0.4) is scored but cannot lead a group
  auto c = s.db.detectLoopCandidates(100, s.query, s.graph);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].keyframe, 1u);
  EXPECT_NEAR(c[0].accumulatedScore, 2.9, 1e-12);

  // Connected to K1 itself: K1 is excluded and sets the minimum to 0.9, so only K6 remains.
  s.graph.connected[100] = {1};
  c = s.db.detectLoopCandidates(100, s.query, s.graph);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].keyframe, 6u);
  EXPECT_NEAR(c[0].accumulatedScore, 0.9, 1e-12);
  // Relocalisation has no exclusion: K1 again.
  EXPECT_EQ(s.db.detectRelocalisationCandidates(s.query, s.graph).at(0).keyframe, 1u);
}

TEST(KeyframeDatabase, EraseAndReplaceUpdateTheIndex) {
  Scene s;
  EXPECT_EQ(s.db.size(), 7u);
  EXPECT_TRUE(s.db.erase(1));
  EXPECT_FALSE(s.db.erase(1));
  EXPECT_FALSE(s.db.contains(1));
  // Without K1: K2 and K3 each 0.8 + 0.8 = 1.6, K4 0.4, K6 0.9; kept > 1.2, ties by id.
  auto c = s.db.detectRelocalisationCandidates(s.query, s.graph);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].keyframe, 2u);
  EXPECT_EQ(c[1].keyframe, 3u);
  EXPECT_NEAR(c[0].accumulatedScore, 1.6, 1e-12);
  // Re-adding under a reused slot with a disjoint bag: K6 alone shares words now... and K6 wins.
  s.db.add(1, bowOf(range(100, 110), 0.1));
  s.db.add(2, bowOf(range(100, 110), 0.1));
  s.db.add(3, bowOf(range(100, 110), 0.1));
  c = s.db.detectRelocalisationCandidates(s.query, s.graph);
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c[0].keyframe, 6u);
  EXPECT_EQ(s.db.bowVector(2)->size(), 11u);
  s.db.clear();
  EXPECT_EQ(s.db.size(), 0u);
  EXPECT_TRUE(s.db.detectRelocalisationCandidates(s.query, s.graph).empty());
}

TEST(KeyframeDatabase, ResultsDoNotDependOnInsertionOrder) {
  KeyframeDatabase a, b;
  ToyGraph none;
  const BowVector q = bowOf(range(0, 9), 0.1);
  for (KeyframeId id : {8, 7, 9}) a.add(id, bowOf(range(0, 8), 0.1, {50}));
  for (KeyframeId id : {9, 7, 8}) b.add(id, bowOf(range(0, 8), 0.1, {50}));
  const auto ca = a.detectRelocalisationCandidates(q, none);
  const auto cb = b.detectRelocalisationCandidates(q, none);
  ASSERT_EQ(ca.size(), 3u);
  ASSERT_EQ(cb.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(ca[i].keyframe, 7u + i);
    EXPECT_EQ(cb[i].keyframe, ca[i].keyframe);
  }
}

}  // namespace
}  // namespace orbis::bow
