// orbis/optim/sparse_cholesky.hpp — CHOLMOD supernodal Cholesky of a symmetric positive-definite
// matrix whose sparsity pattern stays fixed while its values change.
//
// Contract: analyze() takes the upper triangle in compressed-column form (row indices sorted
// within each column) and runs the fill-reducing ordering and symbolic factorisation once;
// factorize() then takes only the values, in pattern order, as often as needed, and returns
// false (no exception) when the matrix is not positive definite; solve() needs a successful
// factorize(). CHOLMOD's types stay inside src/optim/sparse_cholesky.cpp.
#pragma once

#include <memory>
#include <span>

namespace orbis::optim {

// CHOLMOD's supernodal Cholesky of a symmetric positive-definite matrix (upper triangle, compressed
// columns): symbolic analysis once per pattern, numeric factorisation per solve.
class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;
  // @{
  // Movable, not copyable.
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;
  // @}

  // columnStarts has n+1 entries; rowIndices columnStarts[n] entries, each ≤ its column.
  void analyze(int n, std::span<const int> columnStarts, std::span<const int> rowIndices);
  // Whether analyze() has run.
  bool analyzed() const;
  // Factorises with new values in the analysed pattern; false when not positive definite.
  bool factorize(std::span<const double> values);
  // solution may alias rhs.
  bool solve(std::span<const double> rhs, std::span<double> solution);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace orbis::optim
