// orbis/bow/vocabulary.hpp — the bag-of-words vocabulary tree: descriptors to words, weights, scores.
//
// Contract: Vocabulary<Descriptor, Distance> is an immutable view of a VocabularyBlob (the file
// layout, vocabulary_file.hpp); copies share the block. transform() descends the tree greedily:
// at each node it moves to the child whose descriptor is nearest under Distance (ties go to the
// lowest node id) until a leaf, whose word is the descriptor's word. Words of weight 0 (seen in
// every training image) are dropped. The BowVector is L1-normalised, so score() lies in [0, 1].
// The FeatureVector groups feature indices by the node at depth L - levelsUp on the descriptor's
// path (the leaf itself when the leaf is shallower; the root when levelsUp >= L).
// A default-constructed (empty) vocabulary transforms everything to empty vectors; lookup() and
// the node/word accessors need a loaded one. Thread safety: all members are const and may run
// concurrently.
#pragma once

#include <concepts>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "orbis/bow/bow_vector.hpp"
#include "orbis/bow/vocabulary_file.hpp"
#include "orbis/features/descriptor.hpp"
#include "orbis/util/error.hpp"

namespace orbis::bow {

// A fixed-length bit string that can live in place inside the mapped file.
template <class D>
concept BinaryDescriptor =
    std::is_trivially_copyable_v<D> && std::is_standard_layout_v<D> &&
    sizeof(D) == static_cast<std::size_t>(D::kBytes) && D::kBits == 8 * D::kBytes && requires(D d, const D cd) {
      { cd.bytes() } -> std::same_as<const std::uint8_t*>;
      { d.bytes() } -> std::same_as<std::uint8_t*>;
    };

// A vocabulary tree over binary descriptors (DBoW2's model): k-ary, L levels, memory-mapped from
// one checksummed block.
template <BinaryDescriptor Descriptor, DescriptorDistance<Descriptor> Distance>
class Vocabulary {
 public:
  // @{
  // The descriptor and distance types.
  using DescriptorType = Descriptor;
  using DistanceType = Distance;
  // @}

  Vocabulary() = default;

  // Adopts a validated block; throws orbis::Error when its descriptors are not of this type.
  explicit Vocabulary(VocabularyBlob blob, const std::string& source = "vocabulary") : blob_(std::move(blob)) {
    const VocabularyInfo& info = blob_.info();
    if (info.descriptorKind != kBinaryDescriptorKind || info.descriptorBytes != Descriptor::kBytes)
      throw fileError(source, "vocabulary holds " + std::to_string(info.descriptorBytes) +
                                  "-byte descriptors of kind " + std::to_string(info.descriptorKind) +
                                  ", expected " + std::to_string(Descriptor::kBytes) + "-byte binary descriptors");
    descriptors_ = reinterpret_cast<const Descriptor*>(blob_.descriptorBytes());
    nodes_ = blob_.nodes();
    words_ = blob_.words();
  }

  // Maps and validates a vocabulary file; throws orbis::Error naming the file.
  static Vocabulary load(const std::filesystem::path& path) {
    return Vocabulary(VocabularyBlob::load(path), path.string());
  }
  // Writes the vocabulary (atomically).
  void save(const std::filesystem::path& path) const { blob_.save(path); }

  // @{
  // The tree's shape and weighting, and its block.
  bool empty() const { return nodes_ == nullptr; }
  std::uint32_t branching() const { return blob_.info().branching; }
  std::uint32_t depth() const { return blob_.info().depth; }
  Weighting weighting() const { return blob_.info().weighting; }
  Scoring scoring() const { return blob_.info().scoring; }
  std::size_t wordCount() const { return static_cast<std::size_t>(blob_.info().wordCount); }
  std::size_t nodeCount() const { return static_cast<std::size_t>(blob_.info().nodeCount); }
  const VocabularyBlob& blob() const { return blob_; }
  // @}

  // @{
  // A node's descriptor and record, a word's node and weight.
  const Descriptor& nodeDescriptor(NodeId n) const { return descriptors_[n]; }
  const NodeRecord& node(NodeId n) const { return nodes_[n]; }
  NodeId wordNode(WordId w) const { return words_[w].node; }
  float wordWeight(WordId w) const { return words_[w].weight; }
  // @}

  // Where a descriptor lands: its word and the node levelsUp above it.
  struct Lookup {
    // The word.
    WordId word;
    NodeId groupNode;  // node at depth L - levelsUp on the path (see the contract above)
  };

  // Greedy descent for one descriptor.
  Lookup lookup(const Descriptor& d, int levelsUp = 0) const {
    const int groupDepth = static_cast<int>(depth()) - levelsUp;
    const Distance distance{};
    NodeId n = 0;
    NodeId group = 0;
    int level = 0;
    while (nodes_[n].childCount != 0) {
      const NodeId first = nodes_[n].firstChild;
      const NodeId last = first + nodes_[n].childCount;
      NodeId best = first;
      int bestDistance = distance(d, descriptors_[first]);
      for (NodeId c = first + 1; c < last; ++c) {
        const int dc = distance(d, descriptors_[c]);
        if (dc < bestDistance) {
          bestDistance = dc;
          best = c;
        }
      }
      n = best;
      if (++level <= groupDepth) group = n;
    }
    return {nodes_[n].wordId, group};
  }

  // The word a descriptor falls into.
  WordId wordOf(const Descriptor& d) const { return lookup(d).word; }

  // The bag of words of a set of descriptors.
  BowVector transform(std::span<const Descriptor> descriptors) const {
    if (empty()) return {};
    std::vector<WordEntry> entries;
    entries.reserve(descriptors.size());
    for (const Descriptor& d : descriptors) {
      const WordId w = lookup(d).word;
      if (const float weight = words_[w].weight; weight > 0) entries.push_back({w, weight});
    }
    return finish(std::move(entries));
  }

  // BowVector plus FeatureVector (indices into `descriptors`) in one pass.
  void transform(std::span<const Descriptor> descriptors, BowVector& bow, FeatureVector& features,
                 int levelsUp) const {
    bow = {};
    features = {};
    if (empty()) return;
    std::vector<WordEntry> entries;
    std::vector<std::pair<NodeId, std::uint32_t>> groups;
    entries.reserve(descriptors.size());
    groups.reserve(descriptors.size());
    for (std::size_t i = 0; i < descriptors.size(); ++i) {
      const Lookup l = lookup(descriptors[i], levelsUp);
      if (const float weight = words_[l.word].weight; weight > 0) {
        entries.push_back({l.word, weight});
        groups.emplace_back(l.groupNode, static_cast<std::uint32_t>(i));
      }
    }
    bow = finish(std::move(entries));
    features = FeatureVector::fromPairs(std::move(groups));
  }

  // The L1 similarity of two bags of words, in [0, 1].
  double score(const BowVector& a, const BowVector& b) const { return l1Score(a, b); }

 private:
  BowVector finish(std::vector<WordEntry> entries) const {
    const Weighting w = weighting();
    const bool accumulate = w == Weighting::TfIdf || w == Weighting::Tf;
    BowVector v = BowVector::fromUnsorted(std::move(entries), accumulate);
    v.normaliseL1();
    return v;
  }

  VocabularyBlob blob_;
  const Descriptor* descriptors_ = nullptr;
  const NodeRecord* nodes_ = nullptr;
  const WordRecord* words_ = nullptr;
};

// The vocabulary of ORB descriptors the pipeline uses.
using OrbVocabulary = Vocabulary<OrbDescriptor, HammingDistance>;

}  // namespace orbis::bow

namespace orbis {
// The pipeline's vocabulary, named where the system, its map files and its users need it
// without reaching into the threads that use it.
using OrbVocabulary = bow::OrbVocabulary;
}  // namespace orbis
