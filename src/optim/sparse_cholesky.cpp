// CHOLMOD wrapper: one cholmod_common, one pattern matrix, one symbolic factor per structure.
#include "orbis/optim/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace orbis::optim {

struct SparseCholesky::Impl {
  cholmod_common common{};
  cholmod_sparse* matrix = nullptr;
  cholmod_factor* factor = nullptr;
  cholmod_dense* rhs = nullptr;
  bool factorized = false;
  int n = 0;

  Impl() {
    cholmod_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    // AMD alone: METIS costs more than it saves on reduced camera systems of SLAM size.
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_AMD;
    common.postorder = 1;
    common.quick_return_if_not_posdef = 1;
    common.print = 0;
    common.error_handler = nullptr;  // failures are reported through return values
  }
  ~Impl() {
    release();
    cholmod_finish(&common);
  }
  void release() {
    if (rhs) cholmod_free_dense(&rhs, &common);
    if (factor) cholmod_free_factor(&factor, &common);
    if (matrix) cholmod_free_sparse(&matrix, &common);
    factorized = false;
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::analyze(int n, std::span<const int> columnStarts,
                             std::span<const int> rowIndices) {
  Impl& s = *impl_;
  s.release();
  const std::size_t nnz = static_cast<std::size_t>(columnStarts[n]);
  s.n = n;
  s.matrix = cholmod_allocate_sparse(n, n, nnz, /*sorted=*/1, /*packed=*/1, /*stype=*/1,
                                     CHOLMOD_REAL, &s.common);
  if (!s.matrix) throw std::bad_alloc();
  std::copy_n(columnStarts.data(), n + 1, static_cast<int*>(s.matrix->p));
  std::copy_n(rowIndices.data(), nnz, static_cast<int*>(s.matrix->i));
  std::fill_n(static_cast<double*>(s.matrix->x), nnz, 0.0);
  s.factor = cholmod_analyze(s.matrix, &s.common);
  if (!s.factor) throw std::runtime_error("CHOLMOD symbolic analysis failed");
  s.rhs = cholmod_zeros(n, 1, CHOLMOD_REAL, &s.common);
}

bool SparseCholesky::analyzed() const { return impl_->factor != nullptr; }

bool SparseCholesky::factorize(std::span<const double> values) {
  Impl& s = *impl_;
  s.factorized = false;
  if (!s.factor) return false;
  std::memcpy(s.matrix->x, values.data(), s.matrix->nzmax * sizeof(double));
  const int ok = cholmod_factorize(s.matrix, s.factor, &s.common);
  if (!ok || s.common.status != CHOLMOD_OK || s.factor->minor < s.factor->n) return false;
  s.factorized = true;
  return true;
}

bool SparseCholesky::solve(std::span<const double> rhs, std::span<double> solution) {
  Impl& s = *impl_;
  if (!s.factorized) return false;
  std::memmove(s.rhs->x, rhs.data(), static_cast<std::size_t>(s.n) * sizeof(double));
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, s.factor, s.rhs, &s.common);
  if (!x) return false;
  std::memcpy(solution.data(), x->x, static_cast<std::size_t>(s.n) * sizeof(double));
  cholmod_free_dense(&x, &s.common);
  return true;
}

}  // namespace orbis::optim
