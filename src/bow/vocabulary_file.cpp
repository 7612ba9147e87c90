#include "orbis/bow/vocabulary_file.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <new>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "orbis/util/atomic_file.hpp"
#include "orbis/util/enum_names.hpp"
#include "orbis/util/error.hpp"

namespace orbis::bow {

static_assert(std::endian::native == std::endian::little,
              "the vocabulary file is little-endian and mapped in place");

namespace {

constexpr char kMagic[8] = {'O', 'R', 'B', 'I', 'S', 'V', 'O', 'C'};
constexpr std::size_t kAlign = 64;
constexpr std::size_t kTrailerBytes = 8;

struct FileHeader {
  char magic[8];
  std::uint32_t version;
  std::uint32_t headerBytes;
  std::uint32_t branching;
  std::uint32_t depth;
  std::uint32_t weighting;
  std::uint32_t scoring;
  std::uint32_t descriptorKind;
  std::uint32_t descriptorBytes;
  std::uint64_t nodeCount;
  std::uint64_t wordCount;
  std::uint64_t payloadBytes;
};
static_assert(sizeof(FileHeader) == 64);

constexpr std::size_t alignUp(std::size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

struct Offsets {
  std::size_t descriptors, nodes, words, payloadEnd;
};

// Section offsets from the counts; nullopt when the counts overflow (a corrupt header).
std::optional<Offsets> layoutFor(std::uint64_t nodeCount, std::uint64_t wordCount, std::uint64_t descBytes) {
  constexpr std::uint64_t kLimit = std::uint64_t{1} << 40;  // 1 TB: far beyond any real vocabulary
  if (nodeCount > kLimit / 64 || wordCount > kLimit / 64 || descBytes > 4096) return std::nullopt;
  Offsets o{};
  o.descriptors = sizeof(FileHeader);
  o.nodes = alignUp(o.descriptors + nodeCount * descBytes);
  o.words = alignUp(o.nodes + nodeCount * sizeof(NodeRecord));
  o.payloadEnd = alignUp(o.words + wordCount * sizeof(WordRecord));
  return o;
}

struct AlignedDelete {
  void operator()(const std::byte* p) const { ::operator delete[](const_cast<std::byte*>(p), std::align_val_t{kAlign}); }
};

std::shared_ptr<std::byte> allocateBlock(std::size_t size) {
  auto* p = static_cast<std::byte*>(::operator new[](size, std::align_val_t{kAlign}));
  std::memset(p, 0, size);
  return std::shared_ptr<std::byte>(p, AlignedDelete{});
}

constexpr std::uint64_t kP1 = 0x9E3779B185EBCA87ull, kP2 = 0xC2B2AE3D27D4EB4Full,
                        kP3 = 0x165667B19E3779F9ull, kP4 = 0x85EBCA77C2B2AE63ull,
                        kP5 = 0x27D4EB2F165667C5ull;

inline std::uint64_t load64(const unsigned char* p) {
  std::uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}
inline std::uint64_t mixLane(std::uint64_t acc, std::uint64_t input) {
  acc += input * kP2;
  acc = std::rotl(acc, 31);
  return acc * kP1;
}

}  // namespace

std::uint64_t checksum64(const void* data, std::size_t size, std::uint64_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  const unsigned char* const end = p + size;
  std::uint64_t h;
  if (size >= 32) {
    std::uint64_t a = seed + kP1 + kP2, b = seed + kP2, c = seed, d = seed - kP1;
    for (; p + 32 <= end; p += 32) {
      a = mixLane(a, load64(p));
      b = mixLane(b, load64(p + 8));
      c = mixLane(c, load64(p + 16));
      d = mixLane(d, load64(p + 24));
    }
    h = std::rotl(a, 1) + std::rotl(b, 7) + std::rotl(c, 12) + std::rotl(d, 18);
    for (std::uint64_t lane : {a, b, c, d}) h = (h ^ mixLane(0, lane)) * kP1 + kP4;
  } else {
    h = seed + kP5;
  }
  h += static_cast<std::uint64_t>(size);
  for (; p + 8 <= end; p += 8) h = std::rotl(h ^ mixLane(0, load64(p)), 27) * kP1 + kP4;
  for (; p < end; ++p) h = std::rotl(h ^ (*p * kP5), 11) * kP1;
  h ^= h >> 33;
  h *= kP2;
  h ^= h >> 29;
  h *= kP3;
  h ^= h >> 32;
  return h;
}

namespace {
constexpr EnumName<Weighting> kWeightingNames[] = {
    {Weighting::TfIdf, "tf-idf"}, {Weighting::Tf, "tf"}, {Weighting::Idf, "idf"}, {Weighting::Binary, "binary"}};
}  // namespace

std::string_view weightingName(Weighting w) { return enumName(kWeightingNames, w); }

std::optional<Weighting> parseWeighting(std::string_view name) { return findEnumName(kWeightingNames, name); }

void VocabularyBlob::adopt(std::shared_ptr<const std::byte> data, std::size_t size, const std::string& source) {
  const auto fail = [&](const std::string& what) { return fileError(source, what); };
  if (size < sizeof(FileHeader))
    throw fail("truncated: " + std::to_string(size) + " bytes, smaller than the 64-byte header");
  FileHeader h;
  std::memcpy(&h, data.get(), sizeof h);
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0)
    throw fail("not an orbis vocabulary (bad magic; a DBoW2 text vocabulary must first go through `orbis vocab convert`)");
  if (h.version != kVocabularyFormatVersion)
    throw fail("unsupported vocabulary format version " + std::to_string(h.version) + " (this build reads " +
               std::to_string(kVocabularyFormatVersion) + ")");
  if (h.headerBytes != sizeof(FileHeader)) throw fail("corrupt header (header size field)");
  const auto layout = layoutFor(h.nodeCount, h.wordCount, h.descriptorBytes);
  if (!layout || h.payloadBytes != layout->payloadEnd - sizeof(FileHeader))
    throw fail("corrupt header (section sizes disagree with the node and word counts)");
  const std::size_t expected = layout->payloadEnd + kTrailerBytes;
  if (size < expected)
    throw fail("truncated: " + std::to_string(size) + " bytes, the header announces " + std::to_string(expected));
  if (size > expected)
    throw fail("corrupt: " + std::to_string(size - expected) + " unexpected bytes after the checksum");
  std::uint64_t stored;
  std::memcpy(&stored, data.get() + layout->payloadEnd, sizeof stored);
  if (checksum64(data.get(), layout->payloadEnd) != stored) throw fail("checksum mismatch: the file is corrupt");

  if (h.weighting > static_cast<std::uint32_t>(Weighting::Binary))
    throw fail("unknown weighting code " + std::to_string(h.weighting));
  if (h.scoring != static_cast<std::uint32_t>(Scoring::L1))
    throw fail("unsupported scoring code " + std::to_string(h.scoring) + " (only L1 is implemented)");
  if (h.nodeCount == 0 || h.branching < 2 || h.depth < 1) throw fail("corrupt: empty tree or k < 2 or L < 1");

  // Structure: the walk in transform() trusts these invariants, so a crafted file whose checksum
  // matches still cannot send it out of bounds or into a cycle.
  const auto* nodes = reinterpret_cast<const NodeRecord*>(data.get() + layout->nodes);
  const auto* words = reinterpret_cast<const WordRecord*>(data.get() + layout->words);
  const std::uint64_t n = h.nodeCount;
  if (nodes[0].parent != kNoParent) throw fail("corrupt tree: node 0 is not the root");
  std::uint64_t claimed = 0, leaves = 0;
  for (std::uint64_t i = 0; i < n; ++i) {
    const NodeRecord& r = nodes[i];
    if (r.childCount == 0) {
      ++leaves;
      if (r.wordId >= h.wordCount || words[r.wordId].node != i)
        throw fail("corrupt tree: leaf node " + std::to_string(i) + " has no matching word");
      continue;
    }
    if (r.wordId != kNoWord) throw fail("corrupt tree: inner node " + std::to_string(i) + " carries a word");
    if (r.firstChild <= i || std::uint64_t{r.firstChild} + r.childCount > n)
      throw fail("corrupt tree: children of node " + std::to_string(i) + " out of range");
    for (std::uint32_t c = r.firstChild; c < r.firstChild + r.childCount; ++c)
      if (nodes[c].parent != i) throw fail("corrupt tree: node " + std::to_string(c) + " has the wrong parent");
    claimed += r.childCount;
  }
  if (claimed != n - 1 || leaves != h.wordCount)
    throw fail("corrupt tree: node or word counts inconsistent with the links");
  for (std::uint64_t w = 0; w < h.wordCount; ++w)
    if (!std::isfinite(words[w].weight) || words[w].weight < 0)
      throw fail("corrupt: word " + std::to_string(w) + " has a negative or non-finite weight");

  info_ = VocabularyInfo{h.branching, h.depth, static_cast<Weighting>(h.weighting), Scoring::L1,
                         h.descriptorKind, h.descriptorBytes, h.nodeCount, h.wordCount};
  descriptorsOffset_ = layout->descriptors;
  nodesOffset_ = layout->nodes;
  wordsOffset_ = layout->words;
  size_ = size;
  data_ = std::move(data);
}

VocabularyBlob VocabularyBlob::load(const std::filesystem::path& path) {
  const std::string source = path.string();
  const int fd = ::open(source.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw fileError(source, "cannot open: " + std::string(std::strerror(errno)));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw fileError(source, "not a regular file");
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  if (size == 0) {
    ::close(fd);
    throw fileError(source, "truncated: the file is empty");
  }
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) throw fileError(source, "cannot map: " + std::string(std::strerror(errno)));
  std::shared_ptr<const std::byte> data(static_cast<const std::byte*>(map),
                                        [size](const std::byte* p) { ::munmap(const_cast<std::byte*>(p), size); });
  VocabularyBlob blob;
  blob.adopt(std::move(data), size, source);
  return blob;
}

VocabularyBlob VocabularyBlob::build(const VocabularyInfo& info, const std::byte* descriptors,
                                     std::span<const NodeRecord> nodes, std::span<const WordRecord> words,
                                     const std::string& source) {
  if (nodes.size() != info.nodeCount || words.size() != info.wordCount)
    throw fileError(source, "node or word count disagrees with the arrays given");
  const auto layout = layoutFor(info.nodeCount, info.wordCount, info.descriptorBytes);
  if (!layout) throw fileError(source, "vocabulary too large");
  const std::size_t size = layout->payloadEnd + kTrailerBytes;
  auto block = allocateBlock(size);
  FileHeader h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.version = kVocabularyFormatVersion;
  h.headerBytes = sizeof(FileHeader);
  h.branching = info.branching;
  h.depth = info.depth;
  h.weighting = static_cast<std::uint32_t>(info.weighting);
  h.scoring = static_cast<std::uint32_t>(info.scoring);
  h.descriptorKind = info.descriptorKind;
  h.descriptorBytes = info.descriptorBytes;
  h.nodeCount = info.nodeCount;
  h.wordCount = info.wordCount;
  h.payloadBytes = layout->payloadEnd - sizeof(FileHeader);
  std::memcpy(block.get(), &h, sizeof h);
  if (!nodes.empty()) {
    std::memcpy(block.get() + layout->descriptors, descriptors, info.nodeCount * info.descriptorBytes);
    std::memcpy(block.get() + layout->nodes, nodes.data(), nodes.size_bytes());
  }
  if (!words.empty()) std::memcpy(block.get() + layout->words, words.data(), words.size_bytes());
  const std::uint64_t sum = checksum64(block.get(), layout->payloadEnd);
  std::memcpy(block.get() + layout->payloadEnd, &sum, sizeof sum);
  VocabularyBlob blob;
  blob.adopt(std::move(block), size, source);
  return blob;
}

void VocabularyBlob::save(const std::filesystem::path& path) const {
  if (!valid()) throw fileError(path.string(), "no vocabulary to save");
  writeFileAtomically(path, {reinterpret_cast<const char*>(data_.get()), size_});
}

}  // namespace orbis::bow
