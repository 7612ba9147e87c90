// orbis/bow/dbow2_text.hpp — reading and writing DBoW2's text vocabulary (ORB-SLAM2's ORBvoc.txt).
//
// Contract: the text format is a first line "k L scoring weighting" (DBoW2's codes), then one
// line per node except the root, in node-id order: "parent isLeaf d0 ... d(B-1) weight" where
// d are the descriptor's B bytes as decimal integers and weight is the word's IDF weight (0 for
// inner nodes). readDbow2Text accepts any parent order that forms a tree (it renumbers the nodes
// breadth-first, keeping each node's children in file order, and numbers words in that order,
// which for DBoW2's own breadth-first files is the file order of the leaves). Every defect
// throws orbis::Error naming the file and line. writeDbow2Text writes the nodes breadth-first
// with weights at float precision, so text -> binary -> text -> binary reproduces the block.
#pragma once

#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "orbis/bow/vocabulary.hpp"
#include "orbis/util/error.hpp"

namespace orbis::bow {

namespace detail {

// Whole-file read: parsing one buffer is several times faster than a stream per line.
std::string readWholeFile(const std::filesystem::path& path);

class TextCursor {
 public:
  TextCursor(const std::string& text, std::string source) : p_(text.data()), end_(p_ + text.size()), source_(std::move(source)) {}

  bool atEnd() {
    skipBlankLines();
    return p_ == end_;
  }
  std::size_t line() const { return line_; }

  template <class T>
  T number(const char* what) {
    while (p_ != end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r')) ++p_;
    T value{};
    const auto [ptr, ec] = std::from_chars(p_, end_, value);
    if (ec != std::errc{} || ptr == p_)
      throw lineError(source_, line_, std::string("expected ") + what + ", found '" + preview() + "'");
    p_ = ptr;
    return value;
  }
  void endLine() {
    while (p_ != end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\r')) ++p_;
    if (p_ != end_ && *p_ != '\n') throw lineError(source_, line_, "unexpected text '" + preview() + "' at the end of the line");
    if (p_ != end_) {
      ++p_;
      ++line_;
    }
  }

 private:
  void skipBlankLines() {
    for (const char* q = p_;;) {
      while (q != end_ && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
      if (q == end_) { p_ = q; return; }
      if (*q != '\n') return;
      p_ = ++q;
      ++line_;
    }
  }
  std::string preview() const {
    const char* e = p_;
    while (e != end_ && *e != '\n' && e - p_ < 20) ++e;
    return p_ == end_ ? std::string("end of file") : std::string(p_, e);
  }
  const char* p_;
  const char* end_;
  std::string source_;
  std::size_t line_ = 1;
};

}  // namespace detail

template <class Vocab>
Vocab readDbow2Text(const std::filesystem::path& path) {
  using Descriptor = typename Vocab::DescriptorType;
  const std::string source = path.string();
  const std::string text = detail::readWholeFile(path);
  detail::TextCursor in(text, source);
  if (in.atEnd()) throw fileError(source, "empty file, expected the line 'k L scoring weighting'");
  VocabularyInfo info;
  info.branching = in.number<std::uint32_t>("k");
  info.depth = in.number<std::uint32_t>("L");
  const auto scoring = in.number<std::uint32_t>("scoring code");
  const auto weighting = in.number<std::uint32_t>("weighting code");
  if (info.branching < 2 || info.depth < 1) throw lineError(source, 1, "needs k >= 2 and L >= 1");
  if (scoring != 0) throw lineError(source, 1, "scoring code " + std::to_string(scoring) + " is not L1 (0), the only one supported");
  if (weighting > 3) throw lineError(source, 1, "unknown weighting code " + std::to_string(weighting));
  info.weighting = static_cast<Weighting>(weighting);
  info.descriptorBytes = Descriptor::kBytes;
  in.endLine();

  // File order first: parent ids, leaf flags, descriptors, weights.
  struct FileNode {
    std::uint32_t parent;
    bool leaf;
    float weight;
    std::size_t line;
  };
  std::vector<FileNode> fileNodes{{kNoParent, false, 0.0f, 0}};
  std::vector<Descriptor> fileDescriptors{Descriptor{}};
  while (!in.atEnd()) {
    const std::size_t line = in.line();
    const auto id = static_cast<std::uint32_t>(fileNodes.size());
    const auto parent = in.number<std::uint32_t>("parent id");
    if (parent >= id) throw lineError(source, line, "parent " + std::to_string(parent) + " is not an earlier node");
    const int leaf = in.number<int>("isLeaf flag");
    if (leaf != 0 && leaf != 1) throw lineError(source, line, "isLeaf must be 0 or 1");
    if (fileNodes[parent].leaf) throw lineError(source, line, "parent " + std::to_string(parent) + " is a leaf");
    Descriptor d{};
    std::uint8_t* bytes = d.bytes();
    for (int b = 0; b < Descriptor::kBytes; ++b) {
      const int v = in.number<int>("descriptor byte");
      if (v < 0 || v > 255) throw lineError(source, line, "descriptor byte " + std::to_string(v) + " out of 0..255");
      bytes[b] = static_cast<std::uint8_t>(v);
    }
    const double weight = in.number<double>("weight");
    if (!(weight >= 0) || !std::isfinite(weight)) throw lineError(source, line, "weight must be finite and >= 0");
    in.endLine();
    fileNodes.push_back({parent, leaf == 1, static_cast<float>(weight), line});
    fileDescriptors.push_back(d);
  }
  if (fileNodes.size() < 2) throw fileError(source, "no nodes after the header line");

  // Children in file order (counting sort by parent), then breadth-first renumbering.
  const std::size_t n = fileNodes.size();
  std::vector<std::uint32_t> childStart(n + 1, 0), children(n - 1);
  for (std::size_t i = 1; i < n; ++i) ++childStart[fileNodes[i].parent + 1];
  for (std::size_t i = 0; i < n; ++i) childStart[i + 1] += childStart[i];
  {
    std::vector<std::uint32_t> fill(childStart.begin(), childStart.end() - 1);
    for (std::size_t i = 1; i < n; ++i) children[fill[fileNodes[i].parent]++] = static_cast<std::uint32_t>(i);
  }
  std::vector<std::uint32_t> order{0};  // breadth-first order of file ids
  order.reserve(n);
  std::vector<std::uint32_t> newId(n, 0);
  std::vector<NodeRecord> nodes;
  nodes.reserve(n);
  std::vector<Descriptor> descriptors;
  descriptors.reserve(n);
  std::vector<WordRecord> words;
  for (std::size_t q = 0; q < order.size(); ++q) {
    const std::uint32_t f = order[q];
    const std::uint32_t count = childStart[f + 1] - childStart[f];
    const bool isLeaf = f != 0 && fileNodes[f].leaf;
    if (!isLeaf && count == 0) throw lineError(source, fileNodes[f].line, "inner node (isLeaf 0) without children");
    NodeRecord r{0, count, kNoWord, f == 0 ? kNoParent : newId[fileNodes[f].parent]};
    if (count > 0) r.firstChild = static_cast<std::uint32_t>(order.size());
    for (std::uint32_t c = childStart[f]; c < childStart[f + 1]; ++c) {
      newId[children[c]] = static_cast<std::uint32_t>(order.size());
      order.push_back(children[c]);
    }
    if (isLeaf) {
      r.wordId = static_cast<WordId>(words.size());
      words.push_back({static_cast<NodeId>(q), fileNodes[f].weight});
    }
    nodes.push_back(r);
    descriptors.push_back(fileDescriptors[f]);
  }
  info.nodeCount = nodes.size();
  info.wordCount = words.size();
  return Vocab(VocabularyBlob::build(info, reinterpret_cast<const std::byte*>(descriptors.data()), nodes, words, source),
               source);
}

// Writes a vocabulary in DBoW2's text format (ORB-SLAM2's ORBvoc.txt).
template <class Vocab>
void writeDbow2Text(const Vocab& vocabulary, const std::filesystem::path& path) {
  using Descriptor = typename Vocab::DescriptorType;
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw fileError(path.string(), "cannot open for writing");
  std::string line;
  line.reserve(256);
  out << vocabulary.branching() << ' ' << vocabulary.depth() << ' ' << static_cast<int>(vocabulary.scoring()) << ' '
      << static_cast<int>(vocabulary.weighting()) << '\n';
  char buf[32];
  for (NodeId n = 1; n < vocabulary.nodeCount(); ++n) {
    const NodeRecord& r = vocabulary.node(n);
    line.clear();
    line += std::to_string(r.parent);
    line += r.childCount == 0 ? " 1" : " 0";
    const std::uint8_t* bytes = vocabulary.nodeDescriptor(n).bytes();
    for (int b = 0; b < Descriptor::kBytes; ++b) {
      line += ' ';
      line += std::to_string(bytes[b]);
    }
    const float weight = r.childCount == 0 ? vocabulary.wordWeight(r.wordId) : 0.0f;
    const auto res = std::to_chars(buf, buf + sizeof buf, weight);  // shortest exact float text
    line += ' ';
    line.append(buf, res.ptr);
    line += '\n';
    out << line;
  }
  out.flush();
  if (!out) throw fileError(path.string(), "write failed (disk full?)");
}

}  // namespace orbis::bow
