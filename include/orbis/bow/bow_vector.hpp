// orbis/bow/bow_vector.hpp — a frame's bag of words and its feature groups, and their scoring.
//
// Contract: BowVector holds (word id, weight) entries sorted by word id with unique ids; after
// Vocabulary::transform the weights are positive and sum to 1 (L1-normalised), so l1Score of
// two such vectors lies in [0, 1]: 1 for identical vectors, 0 when they share no word.
// FeatureVector groups feature indices by the vocabulary node a few levels above the leaves,
// in compressed rows: nodes sorted ascending, each with its feature indices in ascending order;
// forEachSharedNode walks the nodes two of them share (the candidate groups of guided matching).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

namespace orbis::bow {

// @{
// Ids of words (leaves) and nodes of the vocabulary tree, and a word's weight.
using WordId = std::uint32_t;
using NodeId = std::uint32_t;
using WordValue = double;
// @}

// One word of a bag of words with its weight.
struct WordEntry {
  // @{
  // The word and its weight.
  WordId word;
  WordValue weight;
  // @}
  friend bool operator==(const WordEntry&, const WordEntry&) = default;
};

// A bag of words: (word, weight) entries sorted by word, L1-normalised.
class BowVector {
 public:
  BowVector() = default;

  // Builds from unsorted (word, weight) pairs; duplicates are summed when `accumulate`,
  // otherwise the first weight of a word is kept (IDF and binary weighting count a word once).
  static BowVector fromUnsorted(std::vector<WordEntry> entries, bool accumulate) {
    std::stable_sort(entries.begin(), entries.end(),
                     [](const WordEntry& a, const WordEntry& b) { return a.word < b.word; });
    BowVector v;
    v.entries_.reserve(entries.size());
    for (const WordEntry& e : entries) {
      if (!v.entries_.empty() && v.entries_.back().word == e.word) {
        if (accumulate) v.entries_.back().weight += e.weight;
      } else {
        v.entries_.push_back(e);
      }
    }
    return v;
  }

  // Scales the weights to sum to 1 (no-op for an empty or all-zero vector).
  void normaliseL1() {
    WordValue sum = 0;
    for (const WordEntry& e : entries_) sum += std::abs(e.weight);
    if (sum <= 0) return;
    for (WordEntry& e : entries_) e.weight /= sum;
  }

  // @{
  // Entries: count, emptiness, iteration, one entry, all of them.
  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  auto begin() const { return entries_.begin(); }
  auto end() const { return entries_.end(); }
  const WordEntry& operator[](std::size_t i) const { return entries_[i]; }
  const std::vector<WordEntry>& entries() const { return entries_; }
  // @}

  // Weight of `word`, 0 when absent.
  WordValue weightOf(WordId word) const {
    auto it = std::lower_bound(entries_.begin(), entries_.end(), word,
                               [](const WordEntry& e, WordId w) { return e.word < w; });
    return it != entries_.end() && it->word == word ? it->weight : 0;
  }

  friend bool operator==(const BowVector&, const BowVector&) = default;

 private:
  std::vector<WordEntry> entries_;
};

// DBoW2's L1 score for L1-normalised vectors: 1 - ||a - b||_1 / 2, computed over the shared
// words only (for non-negative weights |x-y| - x - y = -2 min(x, y)).
inline double l1Score(const BowVector& a, const BowVector& b) {
  double sum = 0;
  auto ia = a.begin(), ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->word < ib->word) {
      ++ia;
    } else if (ib->word < ia->word) {
      ++ib;
    } else {
      sum += std::abs(ia->weight - ib->weight) - std::abs(ia->weight) - std::abs(ib->weight);
      ++ia;
      ++ib;
    }
  }
  return -0.5 * sum;
}

// Number of words present in both vectors.
inline std::size_t commonWords(const BowVector& a, const BowVector& b) {
  std::size_t n = 0;
  auto ia = a.begin(), ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->word < ib->word) ++ia;
    else if (ib->word < ia->word) ++ib;
    else { ++n; ++ia; ++ib; }
  }
  return n;
}

// Features grouped by vocabulary node (at a fixed level above the words): the groups matching
// searches compare.
class FeatureVector {
 public:
  FeatureVector() = default;

  // From (node, feature index) pairs in any order.
  static FeatureVector fromPairs(std::vector<std::pair<NodeId, std::uint32_t>> pairs) {
    std::sort(pairs.begin(), pairs.end());
    FeatureVector f;
    f.features_.reserve(pairs.size());
    for (const auto& [node, feature] : pairs) {
      if (f.nodes_.empty() || f.nodes_.back() != node) {
        f.nodes_.push_back(node);
        f.offsets_.push_back(static_cast<std::uint32_t>(f.features_.size()));
      }
      f.features_.push_back(feature);
    }
    f.offsets_.push_back(static_cast<std::uint32_t>(f.features_.size()));
    return f;
  }

  // Number of distinct nodes.
  std::size_t size() const { return nodes_.size(); }
  // @{
  // Emptiness, the i-th node, the features under it, every node, and the number of features.
  bool empty() const { return nodes_.empty(); }
  NodeId node(std::size_t i) const { return nodes_[i]; }
  std::span<const std::uint32_t> featuresOf(std::size_t i) const {
    return {features_.data() + offsets_[i], features_.data() + offsets_[i + 1]};
  }
  const std::vector<NodeId>& nodes() const { return nodes_; }
  std::size_t featureCount() const { return features_.size(); }
  // @}

  friend bool operator==(const FeatureVector&, const FeatureVector&) = default;

 private:
  std::vector<NodeId> nodes_;
  std::vector<std::uint32_t> offsets_;  // size() + 1 entries when non-empty
  std::vector<std::uint32_t> features_;
};

// Calls visit(featuresOfA, featuresOfB) for every vocabulary node that both feature vectors
// hold, in node order: the candidate groups of ORB-SLAM's bag-of-words guided matching.
template <class Visit>
void forEachSharedNode(const FeatureVector& a, const FeatureVector& b, Visit&& visit) {
  std::size_t ia = 0, ib = 0;
  while (ia < a.size() && ib < b.size()) {
    if (a.node(ia) < b.node(ib)) ++ia;
    else if (b.node(ib) < a.node(ia)) ++ib;
    else visit(a.featuresOf(ia++), b.featuresOf(ib++));
  }
}

}  // namespace orbis::bow
