// orbis/bow/vocabulary_training.hpp — building a vocabulary tree by hierarchical k-medians.
//
// Contract: trainVocabulary clusters all training descriptors into k groups (k-means++ seeding,
// then Lloyd iterations with the bit-wise majority as the centre of binary descriptors), and
// recurses into every group of more than one descriptor down to depth L; a group of at most k
// descriptors gets one leaf per distinct descriptor. Each training image is one document for
// the IDF weights, idf(w) = ln(images / images containing w). The result depends only on the
// descriptors, the parameters and the seed — not on the thread count: every node draws from its
// own generator seeded from (seed, node id), and parallel sums are integer counts.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "orbis/bow/vocabulary.hpp"

namespace orbis::bow {

// How a vocabulary is trained (orbis vocab train).
struct TrainingParams {
  std::uint32_t branching = 10;  // k
  std::uint32_t depth = 5;       // L
  // @{
  // Weighting, seed of the k-means++ seeding, and worker threads (the result is the same at any
  // count).
  Weighting weighting = Weighting::TfIdf;
  std::uint64_t seed = 1;
  unsigned threads = 1;
  // @}
  int maxIterations = 30;  // Lloyd iterations per node; most nodes converge well before
  // Called from one thread at a time with (descriptor-levels done, total); may be empty.
  std::function<void(std::size_t, std::size_t)> progress;
};

namespace detail {

// splitmix64: a tiny generator whose output is fixed by its definition on every platform
// (std:: distributions are not), so a seed names the same vocabulary everywhere.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, n) by 128-bit multiply (bias < n / 2^64).
  std::uint64_t below(std::uint64_t n) {
    return static_cast<std::uint64_t>((static_cast<unsigned __int128>(next()) * n) >> 64);
  }
};

inline std::uint64_t nodeSeed(std::uint64_t seed, std::uint64_t node) {
  SplitMix64 a{node};
  SplitMix64 b{seed ^ a.next()};
  return b.next();
}

// Runs fn(begin, end) over [0, n) split in `threads` contiguous chunks.
template <class Fn>
void parallelChunks(std::size_t n, unsigned threads, Fn&& fn) {
  if (threads <= 1 || n < 2) {
    fn(std::size_t{0}, n, 0u);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (n + threads - 1) / threads;
  for (unsigned t = 0; t < threads; ++t) {
    const std::size_t b = std::min(n, t * chunk), e = std::min(n, b + chunk);
    if (b < e) pool.emplace_back([&fn, b, e, t] { fn(b, e, t); });
  }
  for (auto& th : pool) th.join();
}

template <class Descriptor, class Distance>
class KMedians {
 public:
  struct Split {
    std::vector<Descriptor> centers;
    std::vector<std::vector<std::uint32_t>> members;
  };

  KMedians(const std::vector<Descriptor>& all, std::uint32_t k, int maxIterations)
      : all_(all), k_(k), maxIterations_(maxIterations) {}

  Split cluster(const std::vector<std::uint32_t>& items, std::uint64_t seed, unsigned threads) const {
    if (items.size() <= k_) return trivialSplit(items);
    const std::size_t n = items.size();
    const Distance distance{};
    SplitMix64 rng{seed};

    // k-means++ seeding: each next centre drawn with probability proportional to D(x)^2.
    std::vector<Descriptor> centers;
    centers.push_back(all_[items[rng.below(n)]]);
    std::vector<std::uint64_t> minSq(n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto d = static_cast<std::uint64_t>(distance(all_[items[i]], centers[0]));
      minSq[i] = d * d;
    }
    while (centers.size() < k_) {
      std::uint64_t total = 0;
      for (std::uint64_t v : minSq) total += v;
      if (total == 0) break;  // every remaining descriptor equals a centre
      std::uint64_t target = rng.below(total);
      std::size_t pick = 0;
      while (target >= minSq[pick]) target -= minSq[pick++];
      centers.push_back(all_[items[pick]]);
      for (std::size_t i = 0; i < n; ++i) {
        const auto d = static_cast<std::uint64_t>(distance(all_[items[i]], centers.back()));
        minSq[i] = std::min(minSq[i], d * d);
      }
    }

    const std::size_t kc = centers.size();
    constexpr int kBits = Descriptor::kBits;
    std::vector<std::uint32_t> assign(n, 0xFFFFFFFFu);
    const unsigned workers = n >= 16384 ? std::max(1u, threads) : 1u;
    std::vector<std::vector<std::uint32_t>> counts(workers, std::vector<std::uint32_t>(kc * kBits));
    std::vector<std::vector<std::uint32_t>> sizes(workers, std::vector<std::uint32_t>(kc));
    for (int iteration = 0; iteration < maxIterations_; ++iteration) {
      std::atomic<bool> changed{false};
      parallelChunks(n, workers, [&](std::size_t b, std::size_t e, unsigned t) {
        auto& cnt = counts[t];
        auto& sz = sizes[t];
        std::fill(cnt.begin(), cnt.end(), 0u);
        std::fill(sz.begin(), sz.end(), 0u);
        bool localChange = false;
        for (std::size_t i = b; i < e; ++i) {
          const Descriptor& d = all_[items[i]];
          std::uint32_t best = 0;
          int bestDistance = distance(d, centers[0]);
          for (std::uint32_t c = 1; c < kc; ++c) {
            const int dc = distance(d, centers[c]);
            if (dc < bestDistance) {
              bestDistance = dc;
              best = c;
            }
          }
          if (assign[i] != best) {
            assign[i] = best;
            localChange = true;
          }
          ++sz[best];
          std::uint32_t* row = cnt.data() + std::size_t{best} * kBits;
          const std::uint8_t* bytes = d.bytes();
          for (int byte = 0; byte < Descriptor::kBytes; ++byte)
            for (int bit = 0; bit < 8; ++bit) row[byte * 8 + bit] += (bytes[byte] >> bit) & 1u;
        }
        if (localChange) changed.store(true, std::memory_order_relaxed);
      });
      if (!changed.load()) break;
      // Bit-wise majority of each cluster (ties to 0); an emptied cluster keeps its centre.
      for (std::size_t c = 0; c < kc; ++c) {
        std::uint64_t size = 0;
        for (unsigned t = 0; t < workers; ++t) size += sizes[t][c];
        if (size == 0) continue;
        Descriptor center{};
        std::uint8_t* out = center.bytes();
        for (int bit = 0; bit < kBits; ++bit) {
          std::uint64_t ones = 0;
          for (unsigned t = 0; t < workers; ++t) ones += counts[t][c * kBits + static_cast<std::size_t>(bit)];
          if (2 * ones > size) out[bit / 8] |= static_cast<std::uint8_t>(1u << (bit % 8));
        }
        centers[c] = center;
      }
    }

    Split split;
    std::vector<std::vector<std::uint32_t>> members(kc);
    for (std::size_t i = 0; i < n; ++i) members[assign[i]].push_back(items[i]);
    for (std::size_t c = 0; c < kc; ++c) {
      if (members[c].empty()) continue;
      split.centers.push_back(centers[c]);
      split.members.push_back(std::move(members[c]));
    }
    return split;
  }

 private:
  // At most k descriptors: one child per distinct descriptor (duplicates would be dead words).
  Split trivialSplit(const std::vector<std::uint32_t>& items) const {
    Split split;
    for (std::uint32_t item : items) {
      auto it = std::find(split.centers.begin(), split.centers.end(), all_[item]);
      if (it == split.centers.end()) {
        split.centers.push_back(all_[item]);
        split.members.push_back({item});
      } else {
        split.members[static_cast<std::size_t>(it - split.centers.begin())].push_back(item);
      }
    }
    return split;
  }

  const std::vector<Descriptor>& all_;
  std::uint32_t k_;
  int maxIterations_;
};

}  // namespace detail

// images: the descriptors of each training image. Throws orbis::Error("training", ...) on
// parameters that cannot make a tree (k < 2, L < 1, no descriptors, more than 2^32 nodes).
template <class Descriptor, class Distance>
Vocabulary<Descriptor, Distance> trainVocabulary(const std::vector<std::vector<Descriptor>>& images,
                                                 const TrainingParams& params) {
  if (params.branching < 2 || params.depth < 1)
    throw Error("training", "", "needs k >= 2 and L >= 1");
  std::vector<Descriptor> all;
  for (const auto& image : images) all.insert(all.end(), image.begin(), image.end());
  if (all.empty()) throw Error("training", "", "no training descriptors");
  if (all.size() >= 0xFFFFFFFFull) throw Error("training", "", "more than 2^32 descriptors");

  const unsigned threads = std::max(1u, params.threads);
  detail::KMedians<Descriptor, Distance> kmedians(all, params.branching, params.maxIterations);
  std::vector<Descriptor> nodeDescriptors{Descriptor{}};
  std::vector<NodeRecord> nodes{{0, 0, kNoWord, kNoParent}};

  struct Pending {
    NodeId node;
    std::vector<std::uint32_t> items;
  };
  std::vector<Pending> pending(1);
  pending[0].node = 0;
  pending[0].items.resize(all.size());
  for (std::uint32_t i = 0; i < all.size(); ++i) pending[0].items[i] = i;

  const std::size_t progressTotal = all.size() * params.depth;
  std::size_t progressDone = 0;
  std::mutex progressMutex;
  auto report = [&](std::size_t add) {
    if (!params.progress) return;
    std::lock_guard lock(progressMutex);
    progressDone += add;
    params.progress(progressDone, progressTotal);
  };

  // Level by level, so node ids come out breadth-first with contiguous children.
  for (std::uint32_t level = 0; level < params.depth && !pending.empty(); ++level) {
    std::vector<typename detail::KMedians<Descriptor, Distance>::Split> splits(pending.size());
    const bool outer = pending.size() >= threads;
    std::atomic<std::size_t> next{0};
    auto work = [&](unsigned innerThreads) {
      for (std::size_t i; (i = next.fetch_add(1)) < pending.size();) {
        splits[i] = kmedians.cluster(pending[i].items, detail::nodeSeed(params.seed, pending[i].node), innerThreads);
        report(pending[i].items.size());
      }
    };
    if (outer && threads > 1) {
      std::vector<std::thread> pool;
      for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work, 1u);
      for (auto& th : pool) th.join();
    } else {
      work(threads);
    }
    std::vector<Pending> nextLevel;
    for (std::size_t i = 0; i < pending.size(); ++i) {
      auto& split = splits[i];
      if (split.centers.size() < 2 && level > 0) continue;  // one group: the node stays a leaf
      const NodeId parent = pending[i].node;
      if (nodes.size() + split.centers.size() >= 0xFFFFFFFFull) throw Error("training", "", "more than 2^32 nodes");
      nodes[parent].firstChild = static_cast<std::uint32_t>(nodes.size());
      nodes[parent].childCount = static_cast<std::uint32_t>(split.centers.size());
      for (std::size_t c = 0; c < split.centers.size(); ++c) {
        const auto id = static_cast<NodeId>(nodes.size());
        nodes.push_back({0, 0, kNoWord, parent});
        nodeDescriptors.push_back(split.centers[c]);
        if (level + 1 < params.depth && split.members[c].size() > 1)
          nextLevel.push_back({id, std::move(split.members[c])});
      }
    }
    pending = std::move(nextLevel);
  }

  // Words: the leaves in breadth-first order; weights from the training images.
  std::vector<WordRecord> words;
  for (NodeId n = 0; n < nodes.size(); ++n)
    if (nodes[n].childCount == 0) {
      nodes[n].wordId = static_cast<WordId>(words.size());
      words.push_back({n, 1.0f});
    }
  VocabularyInfo info;
  info.branching = params.branching;
  info.depth = params.depth;
  info.weighting = params.weighting;
  info.descriptorBytes = Descriptor::kBytes;
  info.nodeCount = nodes.size();
  info.wordCount = words.size();
  const auto* descBytes = reinterpret_cast<const std::byte*>(nodeDescriptors.data());
  if (params.weighting == Weighting::Idf || params.weighting == Weighting::TfIdf) {
    const Vocabulary<Descriptor, Distance> unweighted(VocabularyBlob::build(info, descBytes, nodes, words, "training"));
    std::vector<std::vector<std::uint32_t>> documents(threads, std::vector<std::uint32_t>(words.size()));
    detail::parallelChunks(images.size(), threads, [&](std::size_t b, std::size_t e, unsigned t) {
      std::vector<WordId> seen;
      for (std::size_t img = b; img < e; ++img) {
        seen.clear();
        for (const Descriptor& d : images[img]) seen.push_back(unweighted.wordOf(d));
        std::sort(seen.begin(), seen.end());
        seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
        for (WordId w : seen) ++documents[t][w];
      }
    });
    const double imageCount = static_cast<double>(images.size());
    for (std::size_t w = 0; w < words.size(); ++w) {
      std::uint64_t containing = 0;
      for (unsigned t = 0; t < threads; ++t) containing += documents[t][w];
      words[w].weight = containing > 0 ? static_cast<float>(std::log(imageCount / static_cast<double>(containing))) : 0.0f;
    }
  }
  return Vocabulary<Descriptor, Distance>(VocabularyBlob::build(info, descBytes, nodes, words, "training"));
}

// A complete k-ary tree of depth L (k^L words) with uniformly random node descriptors and word
// weights in (0, 1], from `seed`. Useless for place recognition; it is the stand-in for a large
// trained vocabulary when only size matters (load-time benchmarks, file-format tests).
template <class Descriptor, class Distance>
Vocabulary<Descriptor, Distance> randomVocabulary(std::uint32_t k, std::uint32_t L, std::uint64_t seed) {
  if (k < 2 || L < 1) throw Error("random vocabulary", "", "needs k >= 2 and L >= 1");
  std::uint64_t total = 1, levelSize = 1;
  for (std::uint32_t l = 0; l < L; ++l) {
    levelSize *= k;
    total += levelSize;
    if (total >= 0xFFFFFFFFull) throw Error("random vocabulary", "", "more than 2^32 nodes");
  }
  detail::SplitMix64 rng{seed};
  std::vector<Descriptor> descriptors(total);
  std::vector<NodeRecord> nodes(total);
  std::vector<WordRecord> words;
  words.reserve(levelSize);
  const std::uint64_t inner = total - levelSize;  // breadth-first: the leaves come last
  for (std::uint64_t n = 0; n < total; ++n) {
    std::uint8_t* bytes = descriptors[n].bytes();
    // The root's descriptor stays zero: never compared, and DBoW2's text format omits it.
    for (int b = 0; n > 0 && b < Descriptor::kBytes; b += 8) {
      const std::uint64_t r = rng.next();
      std::memcpy(bytes + b, &r, static_cast<std::size_t>(std::min(8, Descriptor::kBytes - b)));
    }
    NodeRecord& r = nodes[n];
    r.parent = n == 0 ? kNoParent : static_cast<std::uint32_t>((n - 1) / k);
    if (n < inner) {
      r = {static_cast<std::uint32_t>(n * k + 1), k, kNoWord, r.parent};
    } else {
      r = {0, 0, static_cast<WordId>(words.size()), r.parent};
      words.push_back({static_cast<NodeId>(n), static_cast<float>((rng.next() >> 40) + 1) / 16777216.0f});
    }
  }
  VocabularyInfo info;
  info.branching = k;
  info.depth = L;
  info.descriptorBytes = Descriptor::kBytes;
  info.nodeCount = total;
  info.wordCount = words.size();
  return Vocabulary<Descriptor, Distance>(
      VocabularyBlob::build(info, reinterpret_cast<const std::byte*>(descriptors.data()), nodes, words, "random vocabulary"));
}

}  // namespace orbis::bow
