// orbBlur's integer path (AVX2, views with 3 pixels of context) against the sepFilter2D it
// replaces, bit for bit: widths narrower and wider than a vector, textured, noisy and extreme
// images (rounding ties included).
#include <gtest/gtest.h>

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

TEST(OrbBlur, ViewsWithContextGiveSepFilter2DsBits) {
  cv::RNG rng(17);
  cv::Mat noise(90, 700, CV_8UC1), extremes(90, 700, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  for (int y = 0; y < extremes.rows; ++y)
    for (int x = 0; x < extremes.cols; ++x)
      extremes.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(((x / 3 + y / 2) % 2) ? 255 : rng.uniform(0, 3));
  const cv::Mat parents[] = {test::texturedImage(700, 90, 4, 150), noise, extremes};
  for (const cv::Mat& parent : parents)
    for (const int width : {16, 17, 31, 32, 33, 100, 641})
      for (const int margin : {3, 19}) {
        const cv::Mat view = parent(cv::Rect(margin, margin, width, parent.rows - 2 * margin));
        cv::Mat ours(view.size(), CV_8UC1, cv::Scalar(7));
        orbBlur(view, ours);
        EXPECT_EQ(cv::norm(ours, sepFilterBlur(view), cv::NORM_INF), 0.0) << "width " << width << ", margin " << margin;
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
