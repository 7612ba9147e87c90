// The blur's integer rows 16 pixels at a time: compiled with -mavx2 and called only when the CPU
// has AVX2 (orb_blur.cpp checks). The kernel is orb_blur_kernel.inc.
#include "orb_blur_kernels.hpp"

#if defined(ORBIS_HAVE_AVX2_KERNELS)
#include <immintrin.h>

#include "orbis/features/orb_extractor.hpp"

namespace orbis::detail {
namespace {

struct Avx2BlurOps {
  using V = __m256i;
  static constexpr int kLanes = 16;
  static V widenBytes(const std::uint8_t* p) {
    return _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
  }
  static V loadWords(const std::int16_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
  static void storeWords(std::int16_t* p, V v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
  static V words16(std::int16_t v) { return _mm256_set1_epi16(v); }
  static V words32(int v) { return _mm256_set1_epi32(v); }
  static V add16(V a, V b) { return _mm256_add_epi16(a, b); }
  static V mullo16(V a, V b) { return _mm256_mullo_epi16(a, b); }
  static V bitXor(V a, V b) { return _mm256_xor_si256(a, b); }
  static V bitAnd(V a, V b) { return _mm256_and_si256(a, b); }
  static V unpackLow16(V a, V b) { return _mm256_unpacklo_epi16(a, b); }
  static V unpackHigh16(V a, V b) { return _mm256_unpackhi_epi16(a, b); }
  static V madd(V a, V b) { return _mm256_madd_epi16(a, b); }
  static V add32(V a, V b) { return _mm256_add_epi32(a, b); }
  static V shiftRight32(V a, int n) { return _mm256_srli_epi32(a, n); }
  static void storeBytes(std::uint8_t* out, V low, V high) {
    // Packing the low and high halves restores the pixel order within each 128-bit lane.
    const V words = _mm256_packus_epi32(low, high);
    const V bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(words, words), 0x08);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm256_castsi256_si128(bytes));
  }
};

#include "orb_blur_kernel.inc"

}  // namespace

void blurRowsAvx2(const std::uint8_t* src, std::ptrdiff_t srcStride, int width, int height, std::uint8_t* dst,
                  std::ptrdiff_t dstStride, std::int16_t* sums) {
  blurRows<Avx2BlurOps>(src, srcStride, width, height, dst, dstStride, sums);
}

}  // namespace orbis::detail
#endif
