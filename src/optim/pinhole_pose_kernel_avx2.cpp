// Motion-only BA's pinhole residuals four at a time: compiled with -mavx2 -ffp-contract=off
// (never a fused multiply-add) and called only when the CPU has AVX2 (pinhole_pose_kernel.cpp
// checks). The kernel is pinhole_pose_kernel.inc; contract in orbis/optim/pinhole_pose_kernel.hpp.
#include "orbis/optim/pinhole_pose_kernel.hpp"

#if defined(ORBIS_HAVE_AVX2_KERNELS)
#include <immintrin.h>

namespace orbis::optim::detail {
namespace {

struct Avx2Ops {
  using V = __m256d;
  using M = __m256d;
  static constexpr int kLanes = 4;
  static V load(const double* p) { return _mm256_loadu_pd(p); }
  static void store(double* p, V a) { _mm256_storeu_pd(p, a); }
  static V add(V a, V b) { return _mm256_add_pd(a, b); }
  static V sub(V a, V b) { return _mm256_sub_pd(a, b); }
  static V mul(V a, V b) { return _mm256_mul_pd(a, b); }
  static V div(V a, V b) { return _mm256_div_pd(a, b); }
  static V sqrt(V a) { return _mm256_sqrt_pd(a); }
  static V splat(double a) { return _mm256_set1_pd(a); }
  static V negate(V a) { return _mm256_xor_pd(a, splat(-0.0)); }
  static M lessOrEqual(V a, V b) { return _mm256_cmp_pd(a, b, _CMP_LE_OQ); }
  static V select(M mask, V ifTrue, V ifFalse) { return _mm256_blendv_pd(ifFalse, ifTrue, mask); }
};

#include "pinhole_pose_kernel.inc"

}  // namespace

std::size_t costPinholeBlocksAvx2(const PinholePose& pose, const PinholeResiduals& in, bool huber, double& cost) {
  return costBlocks<Avx2Ops>(pose, in, huber, cost);
}

std::size_t linearizePinholeBlocksAvx2(const PinholePose& pose, const PinholeResiduals& in, bool huber, double& cost,
                                       double* hessian, double* gradient) {
  return linearizeBlocks<Avx2Ops>(pose, in, huber, cost, hessian, gradient);
}

}  // namespace orbis::optim::detail
#endif
