// orbis/optim/reduced_system.hpp — the reduced camera system S·δ = b left after eliminating the
// points, stored block-sparse and solved by dense or sparse (CHOLMOD) Cholesky.
//
// Contract: setPattern() fixes which D×D blocks (i ≤ j) can be non-zero; the values are then
// kept directly in the compressed-column upper triangle CHOLMOD consumes, so accumulating a block
// is a few contiguous adds and no copy is made before factorising. The symbolic factorisation is
// computed once per pattern and reused by every factorize(). solve() returns false when S is not
// positive definite.
#pragma once

#include "orbis/optim/solver_options.hpp"
#include "orbis/optim/sparse_cholesky.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace orbis::optim {

// Where block (i, j), i ≤ j, lives: block column j, i being its position-th stored row block.
struct BlockSlot {
  // @{
  // The block column and the row block's position in it.
  int column = -1;
  int position = 0;
  // @}
};

// Collects the non-zero block pattern without duplicates (a bitmap for modest sizes).
class BlockPatternBuilder {
 public:
  // Starts a pattern of numBlocks × numBlocks blocks.
  void reset(int numBlocks);
  // Marks block (i, j) non-zero.
  void add(int i, int j);
  // Blocks per side.
  int numBlocks() const { return n_; }
  // Row blocks above the diagonal of each block column, sorted.
  std::vector<std::vector<int>> rowsAboveDiagonal() const;

 private:
  int n_ = 0;
  std::vector<std::uint64_t> bits_;
  std::vector<std::vector<int>> lists_;  // used when n is too large for a bitmap
};

// The reduced camera system after the Schur complement, stored by block columns, solved dense
// (small) or by CHOLMOD.
class ReducedCameraSystem {
 public:
  // Lays out the storage for a pattern; kind and denseThreshold choose the solver.
  void setPattern(const BlockPatternBuilder& pattern, int blockDim, LinearSolverKind kind,
                  int denseThreshold);
  // @{
  // Unknowns, blocks per side, and whether CHOLMOD solves it.
  int size() const { return n_ * blockDim_; }
  int numBlocks() const { return n_; }
  bool usesSparse() const { return sparse_; }
  // @}
  BlockSlot slot(int i, int j) const;  // requires i < j and the pair in the pattern
  // Where diagonal block j lives.
  BlockSlot diagonalSlot(int j) const { return {j, static_cast<int>(rowsAbove_[j].size())}; }

  // @{
  // The stored values, and zeroing them.
  std::vector<double>& values() { return values_; }
  void setZero() { std::fill(values_.begin(), values_.end(), 0.0); }
  // @}

  // Adds B to block (i, j) of an off-diagonal slot (i < j).
  template <int D, class Derived>
  void addOffDiagonal(BlockSlot s, const Eigen::MatrixBase<Derived>& block) {
    const int* starts = colStarts_.data() + s.column * D;
    for (int c = 0; c < D; ++c) {
      Eigen::Map<Eigen::Matrix<double, D, 1>>(values_.data() + starts[c] + s.position * D) +=
          block.col(c);
    }
  }
  // Adds the upper triangle of the symmetric block B to diagonal block j.
  template <int D, class Derived>
  void addDiagonal(int j, const Eigen::MatrixBase<Derived>& block) {
    const int* starts = colStarts_.data() + j * D;
    const int offset = static_cast<int>(rowsAbove_[j].size()) * D;
    for (int c = 0; c < D; ++c) {
      double* col = values_.data() + starts[c] + offset;
      for (int r = 0; r <= c; ++r) col[r] += block(r, c);
    }
  }
  // Adds B (i < j) or the upper triangle of B + Bᵀ (i == j): the symmetric contribution of a
  // cross term between two entries of the same block.
  template <int D, class Derived>
  void addSymmetrised(BlockSlot s, bool diagonal, const Eigen::MatrixBase<Derived>& block) {
    if (!diagonal) { addOffDiagonal<D>(s, block); return; }
    const int* starts = colStarts_.data() + s.column * D;
    const int offset = s.position * D;
    for (int c = 0; c < D; ++c) {
      double* col = values_.data() + starts[c] + offset;
      for (int r = 0; r <= c; ++r) col[r] += block(r, c) + block(c, r);
    }
  }

  // Factorises the current values and solves S·x = rhs. False when not positive definite.
  bool solve(std::span<const double> rhs, std::span<double> x);

 private:
  int n_ = 0;
  int blockDim_ = 0;
  bool sparse_ = false;
  std::vector<std::vector<int>> rowsAbove_;
  std::vector<int> denseSlot_;  // n×n position table when small; else binary search
  std::vector<int> colStarts_;
  std::vector<int> rowIndices_;
  std::vector<double> values_;
  SparseCholesky cholmod_;
  Eigen::MatrixXd dense_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

}  // namespace orbis::optim
