// FAST-9 score maps and their corners: the portable code and the run-time choice of the AVX2 code
// (contract in orbis/features/fast_corners.hpp).
#include "orbis/features/fast_corners.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

#include "../util/cpu_dispatch.hpp"
#include "fast_corners_avx2.hpp"

namespace orbis {
namespace {

#include "fast_corner_kernel.inc"

// Whether the AVX2 kernels are both built and runnable here.
bool avx2Kernels() {
#if defined(ORBIS_HAVE_AVX2_KERNELS)
  return detail::cpuHasAvx2();
#else
  return false;
#endif
}

// Whether the AVX-512BW score kernel is both built and runnable here.
bool avx512Kernels() {
#if defined(ORBIS_HAVE_AVX512_KERNELS)
  return avx2Kernels() && detail::cpuHasAvx512bw();
#else
  return false;
#endif
}

FastCode resolve(FastCode code) {
  if (code != FastCode::Best) return code;
  if (avx512Kernels()) return FastCode::Avx512;
  return avx2Kernels() ? FastCode::Avx2 : FastCode::Portable;
}

// The widest vector any path reads past the end of a row of the suppression's copy.
constexpr int kMaxLanes = 32;

}  // namespace

bool fastCodeAvailable(FastCode code) {
  switch (code) {
    case FastCode::Avx2: return avx2Kernels();
    case FastCode::Avx512: return avx512Kernels();
    default: return true;
  }
}

bool fastScoreMapIsVectorised() { return resolve(FastCode::Best) != FastCode::Portable; }

void fastScoreMap(const cv::Mat& image, const cv::Rect& area, int threshold, cv::Mat& scores, FastCode code) {
  CV_Assert(image.type() == CV_8UC1 && area.x >= 3 && area.y >= 3 && area.x + area.width <= image.cols - 3 &&
            area.y + area.height <= image.rows - 3 && threshold >= 0 && threshold < 255);
  CV_Assert(fastCodeAvailable(code));
  scores.create(area.height, area.width, CV_8UC1);
  if (area.empty()) return;
  const std::uint8_t* origin = image.ptr<std::uint8_t>(area.y) + area.x;
  const auto stride = static_cast<std::ptrdiff_t>(image.step1());
  const auto scoreStride = static_cast<std::ptrdiff_t>(scores.step1());
#if defined(ORBIS_HAVE_AVX512_KERNELS)
  if (resolve(code) == FastCode::Avx512) {
    detail::fastScoreRowsAvx512(origin, stride, area.width, area.height, threshold, scores.data, scoreStride);
    return;
  }
#endif
#if defined(ORBIS_HAVE_AVX2_KERNELS)
  if (resolve(code) == FastCode::Avx2) {
    detail::fastScoreRowsAvx2(origin, stride, area.width, area.height, threshold, scores.data, scoreStride);
    return;
  }
#endif
  scoreRows<ScalarOps, ScalarOps>(origin, stride, area.width, area.height, threshold, scores.data, scoreStride);
}

void fastCornersOfScoreMap(const cv::Mat& scores, const cv::Rect& area, int threshold, int keepBelowX,
                           FastScratch& scratch, std::vector<FastCorner>& corners, FastCode code) {
  CV_Assert(scores.type() == CV_8UC1 && (area & cv::Rect(0, 0, scores.cols, scores.rows)) == area);
  CV_Assert(fastCodeAvailable(code));
  const int width = std::min(area.width, keepBelowX - area.x);  // columns whose corners are kept
  if (area.empty() || width <= 0) return;
  threshold = std::clamp(threshold, 1, 255);  // a score of 0 never beats a neighbour (cv::FAST alike)
  // A copy with zeros around it: neighbours outside the area count as 0, as in cv::FAST on the
  // area; columns past `width` stay in, as neighbours.
  const int lead = kMaxLanes;
  const std::ptrdiff_t stride = lead + area.width + kMaxLanes + 2;
  std::vector<std::uint8_t>& padded = scratch.padded;
  padded.resize(static_cast<std::size_t>(stride * (area.height + 2)));
  std::memset(padded.data(), 0, static_cast<std::size_t>(stride + lead));
  for (int y = 0; y < area.height; ++y) {
    std::uint8_t* row = padded.data() + (y + 1) * stride + lead;
    std::memcpy(row, scores.ptr<std::uint8_t>(area.y + y) + area.x, static_cast<std::size_t>(area.width));
    std::memset(row + area.width, 0, static_cast<std::size_t>(stride - area.width));  // and the next lead
  }
  std::memset(padded.data() + (area.height + 1) * stride + lead, 0, static_cast<std::size_t>(stride - lead));
  // No 64-lane suppression: AVX-512 score maps are suppressed by the AVX2 code, which was
  // faster than a 64-lane version (docs/notes/2026-11-29-speed-extraction-vectors.md).
  const bool avx2 = resolve(code) != FastCode::Portable;
  const int lanes = avx2 ? 32 : 1;
  scratch.words.resize(static_cast<std::size_t>((width + lanes - 1) / lanes));
  std::uint32_t* bits = scratch.words.data();
  for (int y = 0; y < area.height; ++y) {
    const std::uint8_t* row = padded.data() + (y + 1) * stride + lead;
#if defined(ORBIS_HAVE_AVX2_KERNELS)
    if (avx2)
      detail::suppressRowBitsAvx2(row - stride, row, row + stride, width, threshold, bits);
    else
#endif
      suppressRowBits<ScalarOps>(row - stride, row, row + stride, width, threshold, bits);
    for (int group = 0, x = 0; x < width; ++group, x += lanes)
      for (std::uint32_t b = bits[group]; b != 0; b &= b - 1) {
        const int column = x + std::countr_zero(b);
        corners.push_back({area.x + column, area.y + y, row[column]});
      }
  }
}

}  // namespace orbis
