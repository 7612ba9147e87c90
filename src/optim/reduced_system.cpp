#include "orbis/optim/reduced_system.hpp"

#include <algorithm>
#include <cmath>

namespace orbis::optim {

namespace {
// Above this many blocks the n² bitmap / slot table would cost more memory than it saves time.
constexpr int kMaxBitmapBlocks = 4096;
constexpr int kMaxSlotTableBlocks = 1024;
}  // namespace

void BlockPatternBuilder::reset(int numBlocks) {
  n_ = numBlocks;
  bits_.clear();
  lists_.clear();
  if (n_ <= kMaxBitmapBlocks) {
    bits_.assign((static_cast<std::size_t>(n_) * n_ + 63) / 64, 0);
  } else {
    lists_.resize(n_);
  }
}

void BlockPatternBuilder::add(int i, int j) {
  if (i == j) return;  // diagonal blocks always exist
  if (i > j) std::swap(i, j);
  if (n_ <= kMaxBitmapBlocks) {
    const std::size_t bit = static_cast<std::size_t>(j) * n_ + i;
    bits_[bit >> 6] |= std::uint64_t{1} << (bit & 63);
  } else {
    lists_[j].push_back(i);
  }
}

std::vector<std::vector<int>> BlockPatternBuilder::rowsAboveDiagonal() const {
  std::vector<std::vector<int>> rows(n_);
  if (n_ <= kMaxBitmapBlocks) {
    for (int j = 0; j < n_; ++j) {
      for (int i = 0; i < j; ++i) {
        const std::size_t bit = static_cast<std::size_t>(j) * n_ + i;
        if (bits_[bit >> 6] >> (bit & 63) & 1) rows[j].push_back(i);
      }
    }
  } else {
    for (int j = 0; j < n_; ++j) {
      rows[j] = lists_[j];
      std::sort(rows[j].begin(), rows[j].end());
      rows[j].erase(std::unique(rows[j].begin(), rows[j].end()), rows[j].end());
    }
  }
  return rows;
}

void ReducedCameraSystem::setPattern(const BlockPatternBuilder& pattern, int blockDim,
                                     LinearSolverKind kind, int denseThreshold) {
  n_ = pattern.numBlocks();
  blockDim_ = blockDim;
  rowsAbove_ = pattern.rowsAboveDiagonal();
  const int D = blockDim;
  const int dim = n_ * D;

  colStarts_.assign(static_cast<std::size_t>(dim) + 1, 0);
  rowIndices_.clear();
  for (int j = 0; j < n_; ++j) {
    for (int c = 0; c < D; ++c) {
      colStarts_[j * D + c] = static_cast<int>(rowIndices_.size());
      for (int i : rowsAbove_[j]) {
        for (int r = 0; r < D; ++r) rowIndices_.push_back(i * D + r);
      }
      for (int r = 0; r <= c; ++r) rowIndices_.push_back(j * D + r);
    }
  }
  colStarts_[dim] = static_cast<int>(rowIndices_.size());
  values_.assign(rowIndices_.size(), 0.0);

  denseSlot_.clear();
  if (n_ <= kMaxSlotTableBlocks) {
    denseSlot_.assign(static_cast<std::size_t>(n_) * n_, -1);
    for (int j = 0; j < n_; ++j) {
      for (std::size_t k = 0; k < rowsAbove_[j].size(); ++k) {
        denseSlot_[static_cast<std::size_t>(j) * n_ + rowsAbove_[j][k]] = static_cast<int>(k);
      }
    }
  }

  sparse_ = kind == LinearSolverKind::SparseCholesky ||
            (kind == LinearSolverKind::Automatic && dim > denseThreshold);
  if (sparse_) {
    cholmod_.analyze(dim, colStarts_, rowIndices_);
  } else {
    dense_.setZero(dim, dim);  // entries outside the pattern are never written again
  }
}

BlockSlot ReducedCameraSystem::slot(int i, int j) const {
  if (!denseSlot_.empty()) return {j, denseSlot_[static_cast<std::size_t>(j) * n_ + i]};
  const auto& rows = rowsAbove_[j];
  const auto it = std::lower_bound(rows.begin(), rows.end(), i);
  return {j, static_cast<int>(it - rows.begin())};
}

bool ReducedCameraSystem::solve(std::span<const double> rhs, std::span<double> x) {
  if (sparse_) {
    if (!cholmod_.factorize(values_)) return false;
    return cholmod_.solve(rhs, x);
  }
  const int dim = size();
  for (int col = 0; col < dim; ++col) {
    // Stored transposed into the lower triangle, the only part LLT reads.
    for (int k = colStarts_[col]; k < colStarts_[col + 1]; ++k) dense_(col, rowIndices_[k]) = values_[k];
  }
  llt_.compute(dense_);
  if (llt_.info() != Eigen::Success) return false;
  Eigen::Map<Eigen::VectorXd>(x.data(), dim) =
      llt_.solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), dim));
  return x.empty() || std::isfinite(x[0]);
}

}  // namespace orbis::optim
