// The pyramid's bilinear resize (contract in orbis/features/linear_resize.hpp).
#include "orbis/features/linear_resize.hpp"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "../util/cpu_dispatch.hpp"
#include "view_context.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define ORBIS_RESIZE_AVX2 1
#endif

namespace orbis {
namespace {

// OpenCV's fixed-point taps for INTER_LINEAR on 8-bit images: the output's centre mapped to
// the source, f = (d + 0.5)·scale − 0.5 in float, the weights (1 − f', f') of its fractional
// part f' scaled by 2048 and rounded. Columns are clamped at the edges (weight 0 on the missing
// neighbour); rows are not, their indices are clamped when read.
void linearTaps(int srcSize, int dstSize, bool clampAtEdges, std::vector<int>& offsets, std::vector<std::int16_t>& taps) {
  const double scale = static_cast<double>(srcSize) / dstSize;
  offsets.resize(static_cast<std::size_t>(dstSize));
  taps.resize(2 * static_cast<std::size_t>(dstSize));
  for (int d = 0; d < dstSize; ++d) {
    float f = static_cast<float>((d + 0.5) * scale - 0.5);
    int s = cvFloor(f);
    f -= static_cast<float>(s);
    if (clampAtEdges) {
      if (s < 0) f = 0.f, s = 0;
      if (s >= srcSize - 1) f = 0.f, s = srcSize - 1;
    }
    offsets[static_cast<std::size_t>(d)] = s;
    taps[2 * static_cast<std::size_t>(d)] = cv::saturate_cast<std::int16_t>((1.f - f) * 2048);
    taps[2 * static_cast<std::size_t>(d) + 1] = cv::saturate_cast<std::int16_t>(f * 2048);
  }
}

#if defined(ORBIS_RESIZE_AVX2)
// One source row resampled along x, 8 outputs at a time: the 16 source bytes from the group's
// first offset, shuffled into the (s[o], s[o + 1]) pairs of its 8 outputs (masks from
// LinearResizer::prepare), weighted and summed in 32 bits, then >> 4 into 16 bits, as OpenCV's
// vertical pass reads them. A gather per group instead was slower than cv::resize here.
__attribute__((target("avx2"))) void horizontalAvx2(const std::uint8_t* row, const int* groupFirst,
                                                   const std::uint8_t* masks, const std::int16_t* taps, int width,
                                                   std::int16_t* out) {
  for (int x = 0, g = 0; x < width; x += 8, ++g) {
    const int at = x + 8 <= width ? x : width - 8;  // the last group shifted back
    const __m256i bytes = _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + groupFirst[g])));
    const __m256i pairs = _mm256_shuffle_epi8(bytes, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(masks + 32 * g)));
    const __m256i weights = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(taps + 2 * at));
    const __m256i sums = _mm256_srai_epi32(_mm256_madd_epi16(pairs, weights), 4);
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packs_epi32(sums, sums), 0x08);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + at), _mm256_castsi256_si128(packed));
  }
}

// Two resampled rows blended along y, 16 outputs at a time, with OpenCV's vector arithmetic:
// the high halves of the 16-bit products, their 16-bit sum, + 2 >> 2, saturated. width >= 16.
__attribute__((target("avx2"))) void verticalAvx2(const std::int16_t* row0, const std::int16_t* row1, std::int16_t w0,
                                                 std::int16_t w1, int width, std::uint8_t* out) {
  const __m256i weight0 = _mm256_set1_epi16(w0), weight1 = _mm256_set1_epi16(w1), two = _mm256_set1_epi16(2);
  for (int x = 0; x < width; x += 16) {
    const int at = x + 16 <= width ? x : width - 16;
    const __m256i a = _mm256_mulhi_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(row0 + at)), weight0);
    const __m256i b = _mm256_mulhi_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(row1 + at)), weight1);
    const __m256i sum = _mm256_srai_epi16(_mm256_add_epi16(_mm256_add_epi16(a, b), two), 2);
    const __m256i bytes = _mm256_permute4x64_epi64(_mm256_packus_epi16(sum, sum), 0x08);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + at), _mm256_castsi256_si128(bytes));
  }
}
#endif

}  // namespace

void LinearResizer::prepare(cv::Size src, cv::Size dst) {
  if (src == srcSize_ && dst == dstSize_) return;
  srcSize_ = src;
  dstSize_ = dst;
  linearTaps(src.width, dst.width, true, xOffsets_, xTaps_);
  linearTaps(src.height, dst.height, false, yOffsets_, yTaps_);
  for (auto& r : rows_) r.resize(static_cast<std::size_t>(dst.width));
  // Per group of 8 outputs (the last shifted back to end at the width): its first offset and the
  // shuffle that puts each output's two neighbours into a 16-bit pair, outputs 0-3 from the low
  // copy of the 16 bytes and 4-7 from the high one. Outputs narrower than 16 (the vertical pass's
  // group) or a group whose neighbours span more than 16 bytes (a shrink by about 1.75 or more)
  // leave the resize to cv::resize.
  const int groups = (dst.width + 7) / 8;
  groupFirst_.assign(static_cast<std::size_t>(groups), 0);
  groupMasks_.assign(32 * static_cast<std::size_t>(groups), 0x80);
  shuffleFits_ = dst.width >= 16;
  for (int g = 0; g < groups && shuffleFits_; ++g) {
    const int at = std::min(8 * g, dst.width - 8);
    const int first = xOffsets_[static_cast<std::size_t>(at)];
    groupFirst_[static_cast<std::size_t>(g)] = first;
    for (int k = 0; k < 8; ++k) {
      const int rel = xOffsets_[static_cast<std::size_t>(at + k)] - first;
      if (rel < 0 || rel + 1 > 15) shuffleFits_ = false;
      std::uint8_t* m = groupMasks_.data() + 32 * g + 4 * k;  // output k's pair: bytes 4k .. 4k + 3
      m[0] = static_cast<std::uint8_t>(rel);
      m[2] = static_cast<std::uint8_t>(rel + 1);
    }
  }
}

const std::int16_t* LinearResizer::horizontalRow(const cv::Mat& src, int y, int keep) {
  for (int s = 0; s < 2; ++s)
    if (rowOf_[s] == y) return rows_[s].data();
  const int s = rowOf_[0] == keep ? 1 : 0;
#if defined(ORBIS_RESIZE_AVX2)
  horizontalAvx2(src.ptr<std::uint8_t>(y), groupFirst_.data(), groupMasks_.data(), xTaps_.data(), dstSize_.width,
                 rows_[s].data());
#else
  (void)src;
#endif
  rowOf_[s] = y;
  return rows_[s].data();
}

void LinearResizer::resizeWithOwnCode(const cv::Mat& src, cv::Mat& dst) {  // after prepare(), which fits
#if defined(ORBIS_RESIZE_AVX2)
  rowOf_[0] = rowOf_[1] = -1;  // a new source
  const int lastRow = src.rows - 1;
  for (int y = 0; y < dst.rows; ++y) {
    const auto i = static_cast<std::size_t>(y);
    const int y0 = std::clamp(yOffsets_[i], 0, lastRow), y1 = std::clamp(yOffsets_[i] + 1, 0, lastRow);
    const std::int16_t* row0 = horizontalRow(src, y0, y1);
    const std::int16_t* row1 = horizontalRow(src, y1, y0);
    verticalAvx2(row0, row1, yTaps_[2 * i], yTaps_[2 * i + 1], dst.cols, dst.ptr<std::uint8_t>(y));
  }
#else
  (void)src;
  (void)dst;
#endif
}

bool LinearResizer::ownCodeAvailable() {
  // The first-use check: orbis's code against this process's cv::resize on noise in views with
  // a border, at the pyramid's factor and at others.
  static const bool available = [] {
#if defined(ORBIS_RESIZE_AVX2)
    if (!detail::cpuHasAvx2()) return false;
    cv::RNG rng(2026);
    const cv::Size sizes[][2] = {{{640, 480}, {533, 400}}, {{101, 37}, {84, 31}}, {{333, 90}, {200, 54}}, {{27, 40}, {16, 33}}};
    LinearResizer probe;
    for (const auto& s : sizes) {
      cv::Mat parent(s[0].height + 32, s[0].width + 32, CV_8UC1);
      rng.fill(parent, cv::RNG::UNIFORM, 0, 256);
      const cv::Mat src = parent(cv::Rect(16, 16, s[0].width, s[0].height));
      cv::Mat expected, ours(s[1], CV_8UC1);
      cv::resize(src, expected, s[1], 0, 0, cv::INTER_LINEAR);
      probe.prepare(src.size(), ours.size());
      if (!probe.shuffleFits_) return false;  // every size here should fit
      probe.resizeWithOwnCode(src, ours);
      if (cv::norm(expected, ours, cv::NORM_INF) != 0.0) return false;
    }
    return true;
#else
    return false;
#endif
  }();
  return available;
}

void LinearResizer::resize(const cv::Mat& src, cv::Mat& dst) {
  CV_Assert(src.type() == CV_8UC1 && dst.type() == CV_8UC1 && !src.empty() && !dst.empty());
  // The groups' 16-byte loads read up to 15 bytes past a row's end.
  lastOwn_ = detail::hasContext(src, 16) && ownCodeAvailable();
  if (lastOwn_) {
    prepare(src.size(), dst.size());
    lastOwn_ = shuffleFits_;
  }
  if (lastOwn_) resizeWithOwnCode(src, dst);
  else cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_LINEAR);
}

}  // namespace orbis
