// orbis/bow/keyframe_database.hpp — inverted index from words to keyframes, and ORB-SLAM's
// loop and relocalisation candidate queries.
//
// Contract: the database stores each keyframe's BowVector (id -> bag of words) and, per word,
// the keyframes containing it. The queries need the covisibility graph only through the small
// CovisibilityGraph concept, so the map module plugs in without this layer knowing keyframes.
//  - detectLoopCandidates(query id, bow, graph): keyframes sharing words with the query, not
//    connected to it in the graph; those sharing more than 80% of the best common-word count
//    are scored; those scoring at least the lowest score between the query and its connected
//    keyframes are grouped with their 10 best covisibles (scores summed over the group members
//    that were scored, the group represented by its best-scoring member); groups above 0.75 x
//    the best group score are returned.
//  - detectRelocalisationCandidates(bow, graph): the same without the exclusion and min score.
// Results are sorted by accumulated score (descending), then keyframe id (ascending), each
// keyframe at most once, so they do not depend on hash or insertion order.
// Thread safety: queries may run concurrently with each other; add/erase/clear lock exclusively.
#pragma once

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <mutex>
#include <optional>
#include <ranges>
#include <shared_mutex>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "orbis/bow/bow_vector.hpp"

namespace orbis::bow {

// A keyframe's id in the database.
using KeyframeId = std::uint64_t;

template <class G>
concept CovisibilityGraph = requires(const G& g, KeyframeId id, std::size_t n) {
  // Every keyframe sharing map points with `id` (excluded from its loop candidates).
  { g.connectedKeyframes(id) } -> std::ranges::input_range;
  // Up to n keyframes sharing the most map points with `id`, most first.
  { g.bestCovisibleKeyframes(id, n) } -> std::ranges::input_range;
};

// A keyframe proposed by a loop or relocalisation query.
struct PlaceCandidate {
  // The keyframe.
  KeyframeId keyframe;
  double accumulatedScore;  // summed over its covisibility group
  double score;             // the keyframe's own score against the query
};

// A keyframe with its L1 score against a query.
struct ScoredKeyframe {
  // @{
  // The keyframe and its score.
  KeyframeId keyframe;
  double score;
  // @}
};

// ORB-SLAM's keyframe database: an inverted index from words to keyframes, with the paper's loop
// and relocalisation queries (common-word, covisibility-group and score filters).
class KeyframeDatabase {
 public:
  // @{
  // ORB-SLAM's filters: a candidate must share 80 % of the best candidate's common words, its group
  // score reach 75 % of the best group's; groups are 10 covisible keyframes.
  static constexpr double kCommonWordsRatio = 0.8;
  static constexpr double kGroupScoreRatio = 0.75;
  static constexpr std::size_t kGroupSize = 10;
  // @}

  // Adds or replaces the keyframe's bag of words.
  void add(KeyframeId id, const BowVector& bow);
  // Removes the keyframe; returns false when it was not present.
  bool erase(KeyframeId id);
  // Removes every keyframe.
  void clear();
  // @{
  // Keyframes held, and whether one is.
  std::size_t size() const;
  bool contains(KeyframeId id) const;
  // @}
  // A keyframe's bag of words, if held.
  std::optional<BowVector> bowVector(KeyframeId id) const;

  // The plain DBoW2 query: the `maxResults` best L1 scores among keyframes sharing a word with
  // `bow` and accepted by `allowed(KeyframeId)`, best first (ties by id).
  template <class Allowed>
  std::vector<ScoredKeyframe> query(const BowVector& bow, std::size_t maxResults, Allowed&& allowed) const {
    std::shared_lock lock(mutex_);
    Scratch s = countCommonWords(bow, [&](std::uint32_t slot) { return !allowed(slots_[slot].id); });
    std::vector<ScoredKeyframe> out;
    out.reserve(s.touched.size());
    for (std::uint32_t slot : s.touched) out.push_back({slots_[slot].id, l1Score(bow, slots_[slot].bow)});
    std::sort(out.begin(), out.end(), [](const ScoredKeyframe& a, const ScoredKeyframe& b) {
      return a.score != b.score ? a.score > b.score : a.keyframe < b.keyframe;
    });
    if (out.size() > maxResults) out.resize(maxResults);
    return out;
  }

  // Loop candidates for a keyframe: keyframes scoring at least as well as its least similar
  // covisible one, not connected to it, filtered by group score.
  template <CovisibilityGraph Graph>
  std::vector<PlaceCandidate> detectLoopCandidates(KeyframeId query, const BowVector& bow, const Graph& graph) const {
    std::shared_lock lock(mutex_);
    std::vector<char> excluded(slots_.size(), 0);
    double minScore = 1.0;
    bool anyConnected = false;
    for (KeyframeId c : graph.connectedKeyframes(query)) {
      if (auto slot = slotOf(c)) {
        excluded[*slot] = 1;
        minScore = std::min(minScore, l1Score(bow, slots_[*slot].bow));
        anyConnected = true;
      }
    }
    if (!anyConnected) minScore = 0;
    if (auto self = slotOf(query)) excluded[*self] = 1;
    return candidates(bow, graph, [&](std::uint32_t slot) { return excluded[slot] != 0; }, minScore);
  }

  // Relocalisation candidates for a frame's bag of words.
  template <CovisibilityGraph Graph>
  std::vector<PlaceCandidate> detectRelocalisationCandidates(const BowVector& bow, const Graph& graph) const {
    std::shared_lock lock(mutex_);
    return candidates(bow, graph, [](std::uint32_t) { return false; }, 0.0);
  }

 private:
  struct Slot {
    KeyframeId id = 0;
    BowVector bow;
  };
  struct Scratch {
    std::vector<std::uint32_t> common;   // per slot: words shared with the query
    std::vector<std::uint32_t> touched;  // slots with common > 0, ascending
  };

  std::optional<std::uint32_t> slotOf(KeyframeId id) const {
    auto it = index_.find(id);
    if (it == index_.end()) return std::nullopt;
    return it->second;
  }

  template <class Excluded>
  Scratch countCommonWords(const BowVector& bow, Excluded&& excluded) const {
    Scratch s;
    s.common.assign(slots_.size(), 0);
    for (const WordEntry& e : bow) {
      if (e.word >= inverted_.size()) continue;
      for (std::uint32_t slot : inverted_[e.word]) {
        if (s.common[slot]++ == 0 && !excluded(slot)) s.touched.push_back(slot);
      }
    }
    std::sort(s.touched.begin(), s.touched.end());
    return s;
  }

  template <class Graph, class Excluded>
  std::vector<PlaceCandidate> candidates(const BowVector& bow, const Graph& graph, Excluded&& excluded,
                                         double minScore) const {
    Scratch s = countCommonWords(bow, excluded);
    if (s.touched.empty()) return {};
    std::uint32_t maxCommon = 0;
    for (std::uint32_t slot : s.touched) maxCommon = std::max(maxCommon, s.common[slot]);
    const double minCommon = kCommonWordsRatio * maxCommon;

    std::vector<double> score(slots_.size(), -1.0);  // -1: not scored
    std::vector<std::uint32_t> accepted;
    for (std::uint32_t slot : s.touched) {
      if (s.common[slot] <= minCommon) continue;
      score[slot] = l1Score(bow, slots_[slot].bow);
      if (score[slot] >= minScore) accepted.push_back(slot);
    }

    std::vector<PlaceCandidate> groups;
    double bestAccumulated = 0;
    for (std::uint32_t slot : accepted) {
      double accumulated = score[slot], bestScore = score[slot];
      KeyframeId best = slots_[slot].id;
      for (KeyframeId n : graph.bestCovisibleKeyframes(slots_[slot].id, kGroupSize)) {
        const auto ns = slotOf(n);
        if (!ns || score[*ns] < 0 || excluded(*ns)) continue;
        accumulated += score[*ns];
        if (score[*ns] > bestScore) {
          bestScore = score[*ns];
          best = n;
        }
      }
      groups.push_back({best, accumulated, bestScore});
      bestAccumulated = std::max(bestAccumulated, accumulated);
    }
    const double retain = kGroupScoreRatio * bestAccumulated;
    std::erase_if(groups, [&](const PlaceCandidate& g) { return g.accumulatedScore <= retain; });
    std::sort(groups.begin(), groups.end(), [](const PlaceCandidate& a, const PlaceCandidate& b) {
      return a.accumulatedScore != b.accumulatedScore ? a.accumulatedScore > b.accumulatedScore : a.keyframe < b.keyframe;
    });
    std::vector<PlaceCandidate> unique;
    std::unordered_set<KeyframeId> seen;
    for (const PlaceCandidate& g : groups)
      if (seen.insert(g.keyframe).second) unique.push_back(g);
    return unique;
  }

  void unindex(std::uint32_t slot);

  mutable std::shared_mutex mutex_;
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> freeSlots_;
  std::unordered_map<KeyframeId, std::uint32_t> index_;
  std::vector<std::vector<std::uint32_t>> inverted_;  // word -> slots
};

}  // namespace orbis::bow
