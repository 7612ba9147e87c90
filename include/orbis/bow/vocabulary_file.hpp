// orbis/bow/vocabulary_file.hpp — the binary vocabulary format and the memory block holding it.
//
// Contract: a vocabulary lives in one immutable, 64-byte-aligned block laid out exactly as the
// file (little-endian):
//   header (64 bytes): magic "ORBISVOC", version, header size, k, L, weighting, scoring,
//     descriptor kind, descriptor bytes, node count, word count, payload bytes;
//   payload, each section starting on a 64-byte boundary: node descriptors (nodeCount x
//     descriptorBytes), NodeRecord[nodeCount], WordRecord[wordCount];
//   trailer: 64-bit checksum (checksum64) of header and payload.
// Nodes are numbered breadth-first with the root at 0, so a node's children are contiguous.
// VocabularyBlob::load maps the file (one mmap, no per-node allocation) and checks size,
// checksum and tree structure before anything reads it: a truncated, corrupt or inconsistent
// file throws orbis::Error naming the file, never yields a half-loaded vocabulary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace orbis::bow {

// Numeric codes are DBoW2's, so its text files convert without a table.
enum class Weighting : std::uint32_t { TfIdf = 0, Tf = 1, Idf = 2, Binary = 3 };
// How bags of words are compared.
enum class Scoring : std::uint32_t { L1 = 0 };  // the only scoring ORB-SLAM uses

// "tf-idf", "tf", "idf" or "binary".
std::string_view weightingName(Weighting w);
std::optional<Weighting> parseWeighting(std::string_view name);  // "tf-idf", "tf", "idf", "binary"

// @{
// Markers: an inner node (no word) and the root (no parent).
inline constexpr std::uint32_t kNoWord = 0xFFFFFFFFu;
inline constexpr std::uint32_t kNoParent = 0xFFFFFFFFu;
// @}
inline constexpr std::uint32_t kBinaryDescriptorKind = 1;  // bit strings compared by Hamming distance

// One node of the tree as stored.
struct NodeRecord {
  std::uint32_t firstChild;  // index of the first child; children are [firstChild, firstChild+childCount)
  std::uint32_t childCount;  // 0 for a leaf (a word)
  std::uint32_t wordId;      // kNoWord for inner nodes
  std::uint32_t parent;      // kNoParent for the root
};
static_assert(sizeof(NodeRecord) == 16);

// One word as stored.
struct WordRecord {
  // Its node.
  std::uint32_t node;
  float weight;  // IDF weight (or 1 for TF / binary weighting)
};
static_assert(sizeof(WordRecord) == 8);

// The tree's shape and weighting, as the file's header holds them.
struct VocabularyInfo {
  std::uint32_t branching = 0;  // k
  std::uint32_t depth = 0;      // L
  // @{
  // Weighting, scoring, descriptor kind and size, node and word counts.
  Weighting weighting = Weighting::TfIdf;
  Scoring scoring = Scoring::L1;
  std::uint32_t descriptorKind = kBinaryDescriptorKind;
  std::uint32_t descriptorBytes = 0;
  std::uint64_t nodeCount = 0;
  std::uint64_t wordCount = 0;
  // @}
};

// The vocabulary file format's version.
inline constexpr std::uint32_t kVocabularyFormatVersion = 1;

// Fast 64-bit non-cryptographic checksum (4 independent multiply-rotate lanes, ~10 GB/s), so
// verifying a 40 MB vocabulary costs a few milliseconds.
std::uint64_t checksum64(const void* data, std::size_t size, std::uint64_t seed = 0);

// A vocabulary file mapped into memory in one block (header, descriptors, nodes, words), checked
// against its checksum.
class VocabularyBlob {
 public:
  VocabularyBlob() = default;

  // Maps and validates a vocabulary file. Throws orbis::Error (file named) on any defect.
  static VocabularyBlob load(const std::filesystem::path& path);

  // Lays out a new block from its parts and seals it with the checksum. Throws orbis::Error
  // with `source` named when the parts do not form a valid tree.
  static VocabularyBlob build(const VocabularyInfo& info, const std::byte* descriptors,
                              std::span<const NodeRecord> nodes, std::span<const WordRecord> words,
                              const std::string& source = "vocabulary");

  // Writes the block byte for byte (atomically: a temporary file renamed into place).
  void save(const std::filesystem::path& path) const;

  // @{
  // Whether a block is held, its header, and its parts.
  bool valid() const { return data_ != nullptr; }
  const VocabularyInfo& info() const { return info_; }
  const std::byte* descriptorBytes() const { return data_.get() + descriptorsOffset_; }
  const NodeRecord* nodes() const { return reinterpret_cast<const NodeRecord*>(data_.get() + nodesOffset_); }
  const WordRecord* words() const { return reinterpret_cast<const WordRecord*>(data_.get() + wordsOffset_); }
  std::span<const std::byte> bytes() const { return {data_.get(), size_}; }
  // @}

 private:
  // Checks header, sizes, checksum and structure of `size` bytes at `data`; fills the offsets.
  void adopt(std::shared_ptr<const std::byte> data, std::size_t size, const std::string& source);

  std::shared_ptr<const std::byte> data_;
  std::size_t size_ = 0;
  VocabularyInfo info_;
  std::size_t descriptorsOffset_ = 0, nodesOffset_ = 0, wordsOffset_ = 0;
};

}  // namespace orbis::bow
