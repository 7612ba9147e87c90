// The blur's integer rows 32 pixels at a time: compiled with -mavx512bw and called only when the
// CPU has AVX-512BW (orb_blur.cpp checks). The kernel is orb_blur_kernel.inc.
#include "orb_blur_kernels.hpp"

#if defined(ORBIS_HAVE_AVX512_KERNELS)
#include <immintrin.h>

#include "orbis/features/orb_extractor.hpp"

namespace orbis::detail {
namespace {

struct Avx512BlurOps {
  using V = __m512i;
  static constexpr int kLanes = 32;
  static V widenBytes(const std::uint8_t* p) {
    return _mm512_cvtepu8_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)));
  }
  static V loadWords(const std::int16_t* p) { return _mm512_loadu_si512(p); }
  static void storeWords(std::int16_t* p, V v) { _mm512_storeu_si512(p, v); }
  static V words16(std::int16_t v) { return _mm512_set1_epi16(v); }
  static V words32(int v) { return _mm512_set1_epi32(v); }
  static V add16(V a, V b) { return _mm512_add_epi16(a, b); }
  static V mullo16(V a, V b) { return _mm512_mullo_epi16(a, b); }
  static V bitXor(V a, V b) { return _mm512_xor_si512(a, b); }
  static V bitAnd(V a, V b) { return _mm512_and_si512(a, b); }
  static V unpackLow16(V a, V b) { return _mm512_unpacklo_epi16(a, b); }
  static V unpackHigh16(V a, V b) { return _mm512_unpackhi_epi16(a, b); }
  static V madd(V a, V b) { return _mm512_madd_epi16(a, b); }
  static V add32(V a, V b) { return _mm512_add_epi32(a, b); }
  static V shiftRight32(V a, unsigned n) { return _mm512_srli_epi32(a, n); }
  static void storeBytes(std::uint8_t* out, V low, V high) {
    // Each 128-bit lane packs back into order; the words are 0 .. 255, so truncation is exact.
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm512_cvtepi16_epi8(_mm512_packus_epi32(low, high)));
  }
};

#include "orb_blur_kernel.inc"

}  // namespace

void blurRowsAvx512(const std::uint8_t* src, std::ptrdiff_t srcStride, int width, int height, std::uint8_t* dst,
                    std::ptrdiff_t dstStride, std::int16_t* sums) {
  blurRows<Avx512BlurOps>(src, srcStride, width, height, dst, dstStride, sums);
}

}  // namespace orbis::detail
#endif
