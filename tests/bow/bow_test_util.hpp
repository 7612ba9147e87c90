// tests/bow/bow_test_util.hpp — synthetic binary descriptors with known cluster structure.
#pragma once

#include <cstdint>
#include <vector>

#include "orbis/bow/vocabulary_training.hpp"
#include "orbis/features/descriptor.hpp"

namespace orbis::bow::test {

inline OrbDescriptor randomDescriptor(detail::SplitMix64& rng) {
  OrbDescriptor d;
  for (auto& w : d.words) w = rng.next();
  return d;
}

inline OrbDescriptor flipBits(OrbDescriptor d, int flips, detail::SplitMix64& rng) {
  for (int i = 0; i < flips; ++i) {
    const int bit = static_cast<int>(rng.below(256));
    d.setBit(bit, !d.bit(bit));
  }
  return d;
}

// `imageCount` images, each showing `perImage` noisy copies of prototypes drawn from a pool of
// `prototypes` random descriptors (each image sees a random window of the pool, so words differ
// in how many images contain them and IDF weights are not all equal).
inline std::vector<std::vector<OrbDescriptor>> syntheticImages(std::uint64_t seed, int imageCount, int perImage,
                                                               int prototypes, int noiseBits) {
  detail::SplitMix64 rng{seed};
  std::vector<OrbDescriptor> pool;
  for (int i = 0; i < prototypes; ++i) pool.push_back(randomDescriptor(rng));
  std::vector<std::vector<OrbDescriptor>> images(static_cast<std::size_t>(imageCount));
  for (auto& image : images) {
    const auto start = rng.below(static_cast<std::uint64_t>(prototypes));
    const auto window = 1 + rng.below(static_cast<std::uint64_t>(prototypes) / 2);
    for (int j = 0; j < perImage; ++j) {
      const auto p = (start + rng.below(window)) % static_cast<std::uint64_t>(prototypes);
      image.push_back(flipBits(pool[p], static_cast<int>(rng.below(static_cast<std::uint64_t>(noiseBits) + 1)), rng));
    }
  }
  return images;
}

inline OrbVocabulary trainSmall(std::uint64_t seed = 7, unsigned threads = 1, std::uint32_t k = 5, std::uint32_t L = 3) {
  TrainingParams params;
  params.branching = k;
  params.depth = L;
  params.seed = seed;
  params.threads = threads;
  return trainVocabulary<OrbDescriptor, HammingDistance>(syntheticImages(11, 40, 120, 300, 12), params);
}

}  // namespace orbis::bow::test
