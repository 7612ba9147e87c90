#include "orbis/bow/flann_index.hpp"

#include <mutex>

#include <flann/flann.hpp>

namespace orbis::bow {

namespace {
using FlannIndex = flann::Index<flann::Hamming<unsigned char>>;

std::mutex& flannRandomMutex() {
  static std::mutex m;
  return m;
}
}  // namespace

struct BinaryDescriptorIndex::Impl {
  std::vector<OrbDescriptor> descriptors;
  BinaryIndexParams params;
  std::unique_ptr<FlannIndex> index;
};

BinaryDescriptorIndex::BinaryDescriptorIndex(std::vector<OrbDescriptor> descriptors, const BinaryIndexParams& params)
    : impl_(std::make_unique<Impl>()) {
  impl_->descriptors = std::move(descriptors);
  impl_->params = params;
  if (impl_->descriptors.empty()) return;
  flann::Matrix<unsigned char> data(impl_->descriptors.front().bytes(), impl_->descriptors.size(),
                                    OrbDescriptor::kBytes);
  std::lock_guard lock(flannRandomMutex());
  flann::seed_random(params.seed);
  if (params.algorithm == BinaryIndexParams::Algorithm::Lsh) {
    impl_->index = std::make_unique<FlannIndex>(
        data, flann::LshIndexParams(static_cast<unsigned>(params.lshTables), static_cast<unsigned>(params.lshKeyBits),
                                    static_cast<unsigned>(params.lshMultiProbe)));
  } else {
    impl_->index = std::make_unique<FlannIndex>(
        data, flann::HierarchicalClusteringIndexParams(params.branching, flann::FLANN_CENTERS_KMEANSPP, params.trees,
                                                       params.leafSize));
  }
  impl_->index->buildIndex();
}

BinaryDescriptorIndex::~BinaryDescriptorIndex() = default;
BinaryDescriptorIndex::BinaryDescriptorIndex(BinaryDescriptorIndex&&) noexcept = default;
BinaryDescriptorIndex& BinaryDescriptorIndex::operator=(BinaryDescriptorIndex&&) noexcept = default;

std::size_t BinaryDescriptorIndex::size() const { return impl_->descriptors.size(); }

std::vector<DescriptorMatch> BinaryDescriptorIndex::nearest(std::span<const OrbDescriptor> queries, int checks) const {
  std::vector<DescriptorMatch> out(queries.size());
  if (queries.empty() || !impl_->index) return out;
  std::vector<OrbDescriptor> q(queries.begin(), queries.end());  // FLANN takes a mutable matrix
  flann::Matrix<unsigned char> qm(q.front().bytes(), q.size(), OrbDescriptor::kBytes);
  std::vector<size_t> indices(q.size());
  std::vector<unsigned int> distances(q.size());
  flann::Matrix<size_t> im(indices.data(), q.size(), 1);
  flann::Matrix<unsigned int> dm(distances.data(), q.size(), 1);
  flann::SearchParams search(checks < 0 ? impl_->params.checks : checks);
  search.cores = 1;
  // Unfound entries keep these sentinels (FLANN leaves them untouched).
  std::fill(indices.begin(), indices.end(), static_cast<size_t>(-1));
  impl_->index->knnSearch(qm, im, dm, 1, search);
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (indices[i] >= impl_->descriptors.size()) continue;
    out[i].index = static_cast<std::int32_t>(indices[i]);
    out[i].distance = hammingDistance(queries[i], impl_->descriptors[indices[i]]);
  }
  return out;
}

std::vector<DescriptorMatch> bruteForceNearest(std::span<const OrbDescriptor> indexed,
                                               std::span<const OrbDescriptor> queries) {
  std::vector<DescriptorMatch> out(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i) {
    DescriptorMatch best;
    for (std::size_t j = 0; j < indexed.size(); ++j) {
      const int d = hammingDistance(queries[i], indexed[j]);
      if (d < best.distance) best = {static_cast<std::int32_t>(j), d};
    }
    out[i] = best;
  }
  return out;
}

}  // namespace orbis::bow
