// The extractor's pre-descriptor blur (orbBlur, contract in orbis/features/orb_extractor.hpp).
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "orbis/features/orb_extractor.hpp"

#include "cpu_dispatch.hpp"
#include "view_context.hpp"

#if defined(__SSE2__) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define ORBIS_BLUR_AVX2 1
#endif

namespace orbis {
namespace {

#if defined(ORBIS_BLUR_AVX2)
// The blur in integers, 16 pixels at a time: column sums of the 7 rows (at most 255 * 256, so
// 16 bits), then row sums of those (32 bits), rounded half to even like sepFilter2D's fixed-point
// path (docs/notes/2026-11-27-own-fast.md: equal on a million pixels, ties included). The column
// sums are kept less 32768, so that the row sums are pairs of signed 16-bit products
// (_mm256_madd_epi16) rather than 32-bit multiplications; the offset, 256 * 32768, is added back
// before rounding, so the sums are exact (docs/notes/2026-11-29-speed-extraction-vectors.md). `src` has 3 valid
// pixels around the width x height area; width >= 16; `sums` holds width + 6 entries.
__attribute__((target("avx2"))) void blurRowsAvx2(const std::uint8_t* src, std::ptrdiff_t srcStride, int width,
                                                  int height, std::uint8_t* dst, std::ptrdiff_t dstStride,
                                                  std::int16_t* sums) {
  constexpr auto& k = OrbExtractor::kBlurTapsQ8;  // symmetric: k[i] == k[6 - i]
  static_assert(k[0] + k[1] + k[2] + k[3] + k[4] + k[5] + k[6] == 256, "the offset below assumes taps summing to 256");
  const __m256i k0 = _mm256_set1_epi16(k[0]), k1 = _mm256_set1_epi16(k[1]), k2 = _mm256_set1_epi16(k[2]),
                k3 = _mm256_set1_epi16(k[3]);
  // (k[a], k[a + 1]) in each 32-bit lane, the first in the low half.
  const __m256i taps01 = _mm256_set1_epi32(k[0] | k[1] << 16), taps23 = _mm256_set1_epi32(k[2] | k[3] << 16),
                taps45 = _mm256_set1_epi32(k[4] | k[5] << 16), taps6 = _mm256_set1_epi32(k[6]);
  const __m256i toSigned = _mm256_set1_epi16(static_cast<short>(0x8000));
  const __m256i offset = _mm256_set1_epi32(256 * 32768);
  const __m256i half = _mm256_set1_epi32(0x7FFF), one = _mm256_set1_epi32(1);
  const int columns = width + 6;  // column sums for x = -3 .. width + 2
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* rows[7];
    for (int i = 0; i < 7; ++i) rows[i] = src + (y + i - 3) * srcStride - 3;
    for (int x = 0; x < columns; x += 16) {
      const int at = x + 16 <= columns ? x : columns - 16;  // the last group shifted back
      __m256i row[7];  // (a lambda would lose the function's AVX2 target)
      for (int i = 0; i < 7; ++i)
        row[i] = _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(rows[i] + at)));
      __m256i s = _mm256_mullo_epi16(_mm256_add_epi16(row[0], row[6]), k0);
      s = _mm256_add_epi16(s, _mm256_mullo_epi16(_mm256_add_epi16(row[1], row[5]), k1));
      s = _mm256_add_epi16(s, _mm256_mullo_epi16(_mm256_add_epi16(row[2], row[4]), k2));
      s = _mm256_add_epi16(s, _mm256_mullo_epi16(row[3], k3));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(sums + at), _mm256_xor_si256(s, toSigned));
    }
    std::uint8_t* out = dst + y * dstStride;
    for (int x = 0; x < width; x += 16) {
      const int at = x + 16 <= width ? x : width - 16;
      __m256i col[7];  // col[j][i]: column at + i + j - 3, less 32768
      for (int j = 0; j < 7; ++j) col[j] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sums + at + j));
      // Unpacking neighbouring shifts pairs column i + j with i + j + 1 in each 32-bit lane: the
      // low halves hold pixels 0-3 and 8-11 of the group, the high halves 4-7 and 12-15.
      __m256i pairs[2][4];
      for (int j = 0; j < 4; ++j) {
        const __m256i next = j < 3 ? col[2 * j + 1] : col[6];  // tap 7 is zero
        pairs[0][j] = _mm256_unpacklo_epi16(col[2 * j], next);
        pairs[1][j] = _mm256_unpackhi_epi16(col[2 * j], next);
      }
      __m256i sum[2];
      for (int h = 0; h < 2; ++h) {
        __m256i t = _mm256_madd_epi16(pairs[h][0], taps01);
        t = _mm256_add_epi32(t, _mm256_madd_epi16(pairs[h][1], taps23));
        t = _mm256_add_epi32(t, _mm256_madd_epi16(pairs[h][2], taps45));
        t = _mm256_add_epi32(t, _mm256_madd_epi16(pairs[h][3], taps6));
        t = _mm256_add_epi32(t, offset);  // the exact sum, 0 .. 255 * 65536
        // Round t / 65536 half to even: add 0x7FFF, plus 1 when the quotient is odd.
        const __m256i odd = _mm256_and_si256(_mm256_srli_epi32(t, 16), one);
        sum[h] = _mm256_srli_epi32(_mm256_add_epi32(_mm256_add_epi32(t, half), odd), 16);
      }
      // Packing the low and high halves restores the pixel order within each 128-bit lane.
      const __m256i words = _mm256_packus_epi32(sum[0], sum[1]);
      const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(words, words), 0x08);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + at), _mm256_castsi256_si128(bytes));
    }
  }
}

// The same 32 pixels at a time, where the CPU has AVX-512BW; width >= 32. (GCC 12's AVX-512
// headers start some intrinsics from a self-initialised "undefined" vector, which its
// uninitialised-use analysis reports when they are inlined here.)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512bw,avx512f"))) void blurRowsAvx512(const std::uint8_t* src, std::ptrdiff_t srcStride,
                                                                int width, int height, std::uint8_t* dst,
                                                                std::ptrdiff_t dstStride, std::int16_t* sums) {
  constexpr auto& k = OrbExtractor::kBlurTapsQ8;
  const __m512i k0 = _mm512_set1_epi16(k[0]), k1 = _mm512_set1_epi16(k[1]), k2 = _mm512_set1_epi16(k[2]),
                k3 = _mm512_set1_epi16(k[3]);
  const __m512i taps01 = _mm512_set1_epi32(k[0] | k[1] << 16), taps23 = _mm512_set1_epi32(k[2] | k[3] << 16),
                taps45 = _mm512_set1_epi32(k[4] | k[5] << 16), taps6 = _mm512_set1_epi32(k[6]);
  const __m512i toSigned = _mm512_set1_epi16(static_cast<short>(0x8000));
  const __m512i offset = _mm512_set1_epi32(256 * 32768);
  const __m512i half = _mm512_set1_epi32(0x7FFF), one = _mm512_set1_epi32(1);
  const int columns = width + 6;
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* rows[7];
    for (int i = 0; i < 7; ++i) rows[i] = src + (y + i - 3) * srcStride - 3;
    for (int x = 0; x < columns; x += 32) {
      const int at = x + 32 <= columns ? x : columns - 32;
      __m512i row[7];
      for (int i = 0; i < 7; ++i)
        row[i] = _mm512_cvtepu8_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows[i] + at)));
      __m512i s = _mm512_mullo_epi16(_mm512_add_epi16(row[0], row[6]), k0);
      s = _mm512_add_epi16(s, _mm512_mullo_epi16(_mm512_add_epi16(row[1], row[5]), k1));
      s = _mm512_add_epi16(s, _mm512_mullo_epi16(_mm512_add_epi16(row[2], row[4]), k2));
      s = _mm512_add_epi16(s, _mm512_mullo_epi16(row[3], k3));
      _mm512_storeu_si512(sums + at, _mm512_xor_si512(s, toSigned));
    }
    std::uint8_t* out = dst + y * dstStride;
    for (int x = 0; x < width; x += 32) {
      const int at = x + 32 <= width ? x : width - 32;
      __m512i col[7];
      for (int j = 0; j < 7; ++j) col[j] = _mm512_loadu_si512(sums + at + j);
      __m512i pairs[2][4];
      for (int j = 0; j < 4; ++j) {
        const __m512i next = j < 3 ? col[2 * j + 1] : col[6];
        pairs[0][j] = _mm512_unpacklo_epi16(col[2 * j], next);
        pairs[1][j] = _mm512_unpackhi_epi16(col[2 * j], next);
      }
      __m512i sum[2];
      for (int h = 0; h < 2; ++h) {
        __m512i t = _mm512_madd_epi16(pairs[h][0], taps01);
        t = _mm512_add_epi32(t, _mm512_madd_epi16(pairs[h][1], taps23));
        t = _mm512_add_epi32(t, _mm512_madd_epi16(pairs[h][2], taps45));
        t = _mm512_add_epi32(t, _mm512_madd_epi16(pairs[h][3], taps6));
        t = _mm512_add_epi32(t, offset);
        const __m512i odd = _mm512_and_si512(_mm512_srli_epi32(t, 16), one);
        sum[h] = _mm512_srli_epi32(_mm512_add_epi32(_mm512_add_epi32(t, half), odd), 16);
      }
      // Each 128-bit lane packs back into order; the words are 0 .. 255, so truncation is exact.
      const __m512i words = _mm512_packus_epi32(sum[0], sum[1]);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + at), _mm512_cvtepi16_epi8(words));
    }
  }
}
#pragma GCC diagnostic pop
#endif

}  // namespace

void orbBlur(const cv::Mat& src, cv::Mat& dst) {
#if defined(ORBIS_BLUR_AVX2)
  // Inside a parent with 3 pixels of context (the pyramid's bordered levels), sepFilter2D reads
  // the parent's pixels, so the integer blur above gives its bits; elsewhere its reflection rules
  // apply and it runs itself.
  if (detail::cpuHasAvx2() && src.type() == CV_8UC1 && src.cols >= 16 && detail::hasContext(src, 3) && src.data != dst.data) {
    dst.create(src.size(), CV_8UC1);
    thread_local std::vector<std::int16_t> sums;
    sums.resize(static_cast<std::size_t>(src.cols) + 6);
    auto* blurRows = src.cols >= 32 && detail::cpuHasAvx512bw() ? blurRowsAvx512 : blurRowsAvx2;
    blurRows(src.ptr<std::uint8_t>(), static_cast<std::ptrdiff_t>(src.step1()), src.cols, src.rows,
             dst.ptr<std::uint8_t>(), static_cast<std::ptrdiff_t>(dst.step1()), sums.data());
    return;
  }
#endif
  // Why not cv::GaussianBlur: on a view into a larger image (our bordered levels) it takes its
  // floating-point path, which rounds differently from ORB-SLAM2's blur of a cloned level (on
  // 1.5% of pixels); on a whole image its bit-exact path costs twice this. sepFilter2D with taps
  // that are exact multiples of 1/256 runs OpenCV's fixed-point separable filter: the same
  // integer sums as the bit-exact path, ties rounded to even instead of up. EuRoC pyramid,
  // one thread: 0.55 ms, against 0.64 (view) and 1.09 (whole levels).
  static const cv::Mat taps = [] {
    cv::Mat k(OrbExtractor::kBlurSize, 1, CV_32F);
    for (int i = 0; i < OrbExtractor::kBlurSize; ++i)
      k.at<float>(i) = static_cast<float>(OrbExtractor::kBlurTapsQ8[static_cast<std::size_t>(i)]) / 256.f;
    return k;
  }();
  cv::sepFilter2D(src, dst, CV_8U, taps, taps, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT_101);
}

}  // namespace orbis
