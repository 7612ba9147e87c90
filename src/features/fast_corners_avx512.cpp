// FAST-9 scores 64 pixels at a time: compiled with -mavx512bw and called only when the CPU has
// AVX-512BW (fast_corners.cpp checks). Same kernel as the AVX2 unit (fast_corner_kernel.inc), so
// the same scores; areas narrower than 64 pixels go to the AVX2 unit. Everything here has internal
// linkage but the entry point. Why a third width: docs/notes/2026-11-29-speed-extraction-vectors.md.
#include "fast_corners_avx2.hpp"

#if defined(ORBIS_HAVE_AVX512_KERNELS)
#include <immintrin.h>

namespace orbis::detail {
namespace {

struct Avx512Ops {
  using V = __m512i;
  static constexpr int kLanes = 64;
  static V load(const std::uint8_t* p) { return _mm512_loadu_si512(p); }
  static void store(std::uint8_t* p, V v) { _mm512_storeu_si512(p, v); }
  static V zero() { return _mm512_setzero_si512(); }
  static V splat(std::uint8_t v) { return _mm512_set1_epi8(static_cast<char>(v)); }
  static V min(V a, V b) { return _mm512_min_epu8(a, b); }
  static V max(V a, V b) { return _mm512_max_epu8(a, b); }
  static V addsat(V a, V b) { return _mm512_adds_epu8(a, b); }
  static V subsat(V a, V b) { return _mm512_subs_epu8(a, b); }
  static V bitAnd(V a, V b) { return _mm512_and_si512(a, b); }
  static V bitXor(V a, V b) { return _mm512_xor_si512(a, b); }
  static V nonZeroMask(V v) { return _mm512_movm_epi8(_mm512_test_epi8_mask(v, v)); }
  static bool allZero(V v) { return _mm512_test_epi8_mask(v, v) == 0; }
  static std::uint64_t nonZeroBits(V v) { return _mm512_test_epi8_mask(v, v); }
};

#include "fast_corner_kernel.inc"

}  // namespace

void fastScoreRowsAvx512(const std::uint8_t* image, std::ptrdiff_t stride, int width, int height, int threshold,
                         std::uint8_t* scores, std::ptrdiff_t scoreStride) {
  if (width < Avx512Ops::kLanes) {
    fastScoreRowsAvx2(image, stride, width, height, threshold, scores, scoreStride);
    return;
  }
  scoreRows<Avx512Ops, Avx512Ops>(image, stride, width, height, threshold, scores, scoreStride);
}

}  // namespace orbis::detail
#endif
