// Motion-only BA's pinhole residuals eight at a time: compiled with -mavx512f -ffp-contract=off
// (AVX-512F has fused multiply-adds of its own, which must not be formed) and called only when
// the CPU has AVX-512F (pinhole_pose_kernel.cpp checks). The kernel is pinhole_pose_kernel.inc;
// contract in orbis/optim/pinhole_pose_kernel.hpp.
#include "orbis/optim/pinhole_pose_kernel.hpp"

#if defined(ORBIS_HAVE_AVX512_KERNELS)
#include <immintrin.h>

namespace orbis::optim::detail {
namespace {

struct Avx512Ops {
  using V = __m512d;
  using M = __mmask8;
  static constexpr int kLanes = 8;
  static V load(const double* p) { return _mm512_loadu_pd(p); }
  static void store(double* p, V a) { _mm512_storeu_pd(p, a); }
  static V add(V a, V b) { return _mm512_add_pd(a, b); }
  static V sub(V a, V b) { return _mm512_sub_pd(a, b); }
  static V mul(V a, V b) { return _mm512_mul_pd(a, b); }
  static V div(V a, V b) { return _mm512_div_pd(a, b); }
  static V sqrt(V a) { return _mm512_sqrt_pd(a); }
  static V splat(double a) { return _mm512_set1_pd(a); }
  static V negate(V a) {
    return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(a), _mm512_castpd_si512(splat(-0.0))));
  }
  static M lessOrEqual(V a, V b) { return _mm512_cmp_pd_mask(a, b, _CMP_LE_OQ); }
  static V select(M mask, V ifTrue, V ifFalse) { return _mm512_mask_blend_pd(mask, ifFalse, ifTrue); }
};

#include "pinhole_pose_kernel.inc"

}  // namespace

std::size_t costPinholeBlocksAvx512(const PinholePose& pose, const PinholeResiduals& in, bool huber, double& cost) {
  return costBlocks<Avx512Ops>(pose, in, huber, cost);
}

std::size_t linearizePinholeBlocksAvx512(const PinholePose& pose, const PinholeResiduals& in, bool huber,
                                         double& cost, double* hessian, double* gradient) {
  return linearizeBlocks<Avx512Ops>(pose, in, huber, cost, hessian, gradient);
}

}  // namespace orbis::optim::detail
#endif
