// FAST-9 scores and non-maximum suppression, 32 pixels at a time: compiled with -mavx2 and called
// only when the CPU has AVX2 (fast_corners.cpp checks). Everything here has internal linkage but
// the two entry points, and nothing instantiates a library template, so no AVX2 code can stand in
// for a baseline function at link time.
#include "fast_corners_avx2.hpp"

#if defined(ORBIS_HAVE_AVX2_KERNELS)
#include <immintrin.h>


namespace orbis::detail {
namespace {

struct Avx2Ops {
  using V = __m256i;
  static constexpr int kLanes = 32;
  static V load(const std::uint8_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
  static void store(std::uint8_t* p, V v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
  static V zero() { return _mm256_setzero_si256(); }
  static V splat(std::uint8_t v) { return _mm256_set1_epi8(static_cast<char>(v)); }
  static V min(V a, V b) { return _mm256_min_epu8(a, b); }
  static V max(V a, V b) { return _mm256_max_epu8(a, b); }
  static V addsat(V a, V b) { return _mm256_adds_epu8(a, b); }
  static V subsat(V a, V b) { return _mm256_subs_epu8(a, b); }
  static V bitAnd(V a, V b) { return _mm256_and_si256(a, b); }
  static V bitXor(V a, V b) { return _mm256_xor_si256(a, b); }
  static V nonZeroMask(V v) { return _mm256_xor_si256(_mm256_cmpeq_epi8(v, zero()), _mm256_set1_epi8(-1)); }
  static bool allZero(V v) { return _mm256_testz_si256(v, v) != 0; }
  static std::uint64_t nonZeroBits(V v) {
    return static_cast<std::uint32_t>(~_mm256_movemask_epi8(_mm256_cmpeq_epi8(v, zero())));
  }
};

// Areas 16 to 31 pixels wide (the fallback cells of a level's edge): 16 pixels at a time.
struct Avx2NarrowOps {
  using V = __m128i;
  static constexpr int kLanes = 16;
  static V load(const std::uint8_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); }
  static void store(std::uint8_t* p, V v) { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v); }
  static V zero() { return _mm_setzero_si128(); }
  static V splat(std::uint8_t v) { return _mm_set1_epi8(static_cast<char>(v)); }
  static V min(V a, V b) { return _mm_min_epu8(a, b); }
  static V max(V a, V b) { return _mm_max_epu8(a, b); }
  static V addsat(V a, V b) { return _mm_adds_epu8(a, b); }
  static V subsat(V a, V b) { return _mm_subs_epu8(a, b); }
  static V bitAnd(V a, V b) { return _mm_and_si128(a, b); }
  static V bitXor(V a, V b) { return _mm_xor_si128(a, b); }
  static V nonZeroMask(V v) { return _mm_xor_si128(_mm_cmpeq_epi8(v, zero()), _mm_set1_epi8(-1)); }
  static bool allZero(V v) { return _mm_testz_si128(v, v) != 0; }
  static std::uint64_t nonZeroBits(V v) {
    return static_cast<std::uint64_t>(~_mm_movemask_epi8(_mm_cmpeq_epi8(v, zero())) & 0xFFFF);
  }
};

#include "fast_corner_kernel.inc"

}  // namespace

void fastScoreRowsAvx2(const std::uint8_t* image, std::ptrdiff_t stride, int width, int height, int threshold,
                       std::uint8_t* scores, std::ptrdiff_t scoreStride) {
  scoreRows<Avx2Ops, Avx2NarrowOps>(image, stride, width, height, threshold, scores, scoreStride);
}

void suppressRowBitsAvx2(const std::uint8_t* above, const std::uint8_t* row, const std::uint8_t* below, int width,
                         int threshold, std::uint32_t* words) {
  suppressRowBits<Avx2Ops>(above, row, below, width, threshold, words);
}

}  // namespace orbis::detail
#endif
