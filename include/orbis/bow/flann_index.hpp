// orbis/bow/flann_index.hpp — approximate nearest-neighbour search over ORB descriptors (FLANN).
//
// Contract: BinaryDescriptorIndex copies the descriptors it is built on and answers, for each
// query, the nearest indexed descriptor it finds (index -1 when the search finds none) with
// its exact Hamming distance. It is the alternative to exhaustive matching when one frame is
// matched against a large descriptor set (relocalisation against a whole map, or many frames).
//  - HierarchicalClustering (default): FLANN's hierarchical k-medoids tree for binary data
//    (Muja & Lowe 2012), k-means++ centres drawn from FLANN's generator seeded with `seed` (under
//    a lock, since FLANN's generator is the process-wide rand()): deterministic.
//  - Lsh: FLANN's multi-probe LSH. FLANN draws the hash bits from std::random_device, so its
//    answers may differ between runs: use it for comparison, not where results must repeat.
// bruteForceNearest is the exact reference (lowest distance, ties to the lowest index).
// FLANN stays private to the library: this header does not include it.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "orbis/features/descriptor.hpp"

namespace orbis::bow {

// The nearest indexed descriptor to a query.
struct DescriptorMatch {
  std::int32_t index = -1;  // into the indexed set; -1: none found
  // Its Hamming distance (kBits + 1 when none was found).
  int distance = OrbDescriptor::kBits + 1;
};

// How the FLANN index over binary descriptors is built and searched.
struct BinaryIndexParams {
  // Hierarchical clustering (the default) or locality-sensitive hashing.
  enum class Algorithm { HierarchicalClustering, Lsh };
  // The index's algorithm.
  Algorithm algorithm = Algorithm::HierarchicalClustering;
  // Hierarchical clustering: branching, number of parallel trees, leaf size.
  int branching = 32;
  // @{
  // Hierarchical clustering: parallel trees and leaf size.
  int trees = 4;
  int leafSize = 100;
  // @}
  // LSH: tables, key bits, multi-probe level.
  int lshTables = 12;
  // @{
  // LSH: key bits and multi-probe level.
  int lshKeyBits = 20;
  int lshMultiProbe = 2;
  // @}
  // Search effort: leaves visited per query (hierarchical clustering; ignored by LSH).
  int checks = 256;
  // Seed of the index's random choices.
  std::uint32_t seed = 1;
};

// An approximate nearest-neighbour index over binary descriptors (FLANN).
class BinaryDescriptorIndex {
 public:
  // Builds the index over descriptors.
  explicit BinaryDescriptorIndex(std::vector<OrbDescriptor> descriptors, const BinaryIndexParams& params = {});
  ~BinaryDescriptorIndex();
  // @{
  // Movable, not copyable.
  BinaryDescriptorIndex(BinaryDescriptorIndex&&) noexcept;
  BinaryDescriptorIndex& operator=(BinaryDescriptorIndex&&) noexcept;
  // @}

  // Descriptors indexed.
  std::size_t size() const;
  // One match per query; `checks` < 0 uses params.checks.
  std::vector<DescriptorMatch> nearest(std::span<const OrbDescriptor> queries, int checks = -1) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Exact nearest neighbours by exhaustive search: the reference the index is measured against.
std::vector<DescriptorMatch> bruteForceNearest(std::span<const OrbDescriptor> indexed,
                                               std::span<const OrbDescriptor> queries);

}  // namespace orbis::bow
