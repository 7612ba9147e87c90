// orbBlur's integer paths (AVX2 and AVX-512 where the CPU has them, each forced in turn; views
// with 3 pixels of context) against the sepFilter2D they replace and against the exact sum
// rounded half to even, bit for bit: widths narrower and wider than a vector, textured, noisy and
// extreme images (rounding ties included). The second reference keeps the test meaningful where
// orbBlur itself falls back to sepFilter2D.
#include <gtest/gtest.h>

#include <vector>

#include <opencv2/imgproc.hpp>

#include "features/feature_test_util.hpp"
#include "orbis/features/orb_extractor.hpp"

namespace orbis {
namespace {

cv::Mat sepFilterBlur(const cv::Mat& src) {
  cv::Mat taps(OrbExtractor::kBlurSize, 1, CV_32F);
  for (int i = 0; i < OrbExtractor::kBlurSize; ++i)
    taps.at<float>(i) = static_cast<float>(OrbExtractor::kBlurTapsQ8[static_cast<std::size_t>(i)]) / 256.f;
  cv::Mat out;
  cv::sepFilter2D(src, out, CV_8U, taps, taps, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT_101);
  return out;
}

// Σ_r k_r Σ_c k_c I / 65536 in exact integers, rounded half to even, from the parent's pixels.
cv::Mat integerBlur(const cv::Mat& view) {
  const auto& k = OrbExtractor::kBlurTapsQ8;
  cv::Mat out(view.size(), CV_8UC1);
  for (int y = 0; y < view.rows; ++y)
    for (int x = 0; x < view.cols; ++x) {
      std::int64_t sum = 0;
      for (int r = 0; r < 7; ++r)
        for (int c = 0; c < 7; ++c) sum += k[r] * k[c] * view.ptr<std::uint8_t>(y + r - 3)[x + c - 3];
      std::int64_t q = sum >> 16;
      const std::int64_t rest = sum & 0xFFFF;
      if (rest > 0x8000 || (rest == 0x8000 && (q & 1))) ++q;
      out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(q);
    }
  return out;
}

TEST(OrbBlur, ViewsWithContextGiveSepFilter2DsBits) {
  cv::RNG rng(17);
  cv::Mat noise(90, 700, CV_8UC1), extremes(90, 700, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  for (int y = 0; y < extremes.rows; ++y)
    for (int x = 0; x < extremes.cols; ++x)
      extremes.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(((x / 3 + y / 2) % 2) ? 255 : rng.uniform(0, 3));
  const cv::Mat parents[] = {test::texturedImage(700, 90, 4, 150), noise, extremes};
  std::vector<BlurCode> codes;
  for (const BlurCode code : {BlurCode::Best, BlurCode::Portable, BlurCode::Avx2, BlurCode::Avx512})
    if (blurCodeAvailable(code)) codes.push_back(code);
  for (const cv::Mat& parent : parents)
    for (const int width : {16, 17, 31, 32, 33, 100, 641})
      for (const int margin : {3, 19}) {
        const cv::Mat view = parent(cv::Rect(margin, margin, width, parent.rows - 2 * margin));
        const cv::Mat exact = integerBlur(view);
        for (const BlurCode code : codes) {
          cv::Mat ours(view.size(), CV_8UC1, cv::Scalar(7));
          orbBlur(view, ours, code);
          EXPECT_EQ(cv::norm(ours, exact, cv::NORM_INF), 0.0)
              << "code " << static_cast<int>(code) << ", width " << width << ", margin " << margin;
        }
        EXPECT_EQ(cv::norm(sepFilterBlur(view), exact, cv::NORM_INF), 0.0) << "width " << width << ", margin " << margin;
      }
}

TEST(OrbBlur, WritesIntoAViewInPlace) {
  // The extractor blurs into the interior of a bordered buffer.
  const cv::Mat parent = test::texturedImage(200, 120, 9, 150);
  const cv::Mat view = parent(cv::Rect(19, 19, 162, 82));
  cv::Mat buffer(120, 200, CV_8UC1, cv::Scalar(3));
  cv::Mat target = buffer(cv::Rect(19, 19, 162, 82));
  orbBlur(view, target);
  EXPECT_EQ(target.data, buffer.ptr<std::uint8_t>(19) + 19);
  EXPECT_EQ(cv::norm(target, sepFilterBlur(view), cv::NORM_INF), 0.0);
  EXPECT_EQ(buffer.at<std::uint8_t>(0, 0), 3);
}

}  // namespace
}  // namespace orbis
