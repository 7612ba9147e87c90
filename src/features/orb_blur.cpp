// The extractor's pre-descriptor blur (orbBlur, contract in orbis/features/orb_extractor.hpp):
// the run-time choice between the integer rows of orb_blur_avx512.cpp / orb_blur_avx2.cpp and
// OpenCV's sepFilter2D.
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "orbis/features/orb_extractor.hpp"

#include "../util/cpu_dispatch.hpp"
#include "orb_blur_kernels.hpp"
#include "view_context.hpp"

namespace orbis {
namespace {

// The integer rows' minimum width per code.
int minimumWidth(BlurCode code) { return code == BlurCode::Avx512 ? 32 : 16; }

// The code that blurs `src`: `code` itself unless Best; Best picks the widest available code
// whose minimum width `src` meets.
BlurCode resolve(BlurCode code, const cv::Mat& src) {
  if (code != BlurCode::Best) return code;
  for (const BlurCode c : {BlurCode::Avx512, BlurCode::Avx2})
    if (blurCodeAvailable(c) && src.cols >= minimumWidth(c)) return c;
  return BlurCode::Portable;
}

}  // namespace

bool blurCodeAvailable(BlurCode code) {
  switch (code) {
#if defined(ORBIS_HAVE_AVX512_KERNELS)
    case BlurCode::Avx512: return detail::cpuHasAvx512bw();
#endif
#if defined(ORBIS_HAVE_AVX2_KERNELS)
    case BlurCode::Avx2: return detail::cpuHasAvx2();
#endif
    case BlurCode::Best:
    case BlurCode::Portable: return true;
    default: return false;
  }
}

void orbBlur(const cv::Mat& src, cv::Mat& dst, BlurCode code) {
  CV_Assert(blurCodeAvailable(code));
  code = resolve(code, src);
  // Inside a parent with 3 pixels of context (the pyramid's bordered levels), sepFilter2D reads
  // the parent's pixels, so the integer rows give its bits; elsewhere its reflection rules apply
  // and it runs itself.
  if (code != BlurCode::Portable && src.type() == CV_8UC1 && src.cols >= minimumWidth(code) &&
      detail::hasContext(src, 3) && src.data != dst.data) {
    dst.create(src.size(), CV_8UC1);
    thread_local std::vector<std::int16_t> sums;
    sums.resize(static_cast<std::size_t>(src.cols) + 6);
    auto* blurRows = code == BlurCode::Avx512 ? detail::blurRowsAvx512 : detail::blurRowsAvx2;
    blurRows(src.ptr<std::uint8_t>(), static_cast<std::ptrdiff_t>(src.step1()), src.cols, src.rows,
             dst.ptr<std::uint8_t>(), static_cast<std::ptrdiff_t>(dst.step1()), sums.data());
    return;
  }
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
