// FAST score-map tests: every code path (portable, AVX2 and AVX-512 where the CPU has them) against cv::FAST on
// whole images and on sub-areas of a lower-threshold map, as OrbExtractor reads them.
#include <gtest/gtest.h>

#include <tuple>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "features/feature_test_util.hpp"
#include "orbis/features/fast_corners.hpp"

namespace orbis {
namespace {

using CornerTuple = std::tuple<int, int, int>;  // x, y, score in image coordinates

// cv::FAST with suppression over `area` (plus its 3-pixel context), in image coordinates, keeping
// x < keepBelowX.
std::vector<CornerTuple> openCvCorners(const cv::Mat& image, const cv::Rect& area, int threshold, int keepBelowX) {
  std::vector<cv::KeyPoint> keypoints;
  cv::FAST(image(cv::Rect(area.x - 3, area.y - 3, area.width + 6, area.height + 6)), keypoints, threshold, true);
  std::vector<CornerTuple> out;
  for (const cv::KeyPoint& k : keypoints) {
    const int x = static_cast<int>(k.pt.x) + area.x - 3, y = static_cast<int>(k.pt.y) + area.y - 3;
    if (x < keepBelowX) out.emplace_back(x, y, static_cast<int>(k.response));
  }
  return out;
}

// The same from a score map of `mapArea` at `mapThreshold`.
std::vector<CornerTuple> mapCorners(const cv::Mat& image, const cv::Rect& mapArea, int mapThreshold,
                                    const cv::Rect& area, int threshold, int keepBelowX, FastCode code) {
  cv::Mat scores;
  fastScoreMap(image, mapArea, mapThreshold, scores, code);
  FastScratch scratch;
  std::vector<FastCorner> corners;
  fastCornersOfScoreMap(scores, area - mapArea.tl(), threshold, keepBelowX - mapArea.x, scratch, corners, code);
  std::vector<CornerTuple> out;
  for (const FastCorner& c : corners) out.emplace_back(c.x + mapArea.x, c.y + mapArea.y, c.score);
  return out;
}

std::vector<FastCode> availableCodes() {
  std::vector<FastCode> codes{FastCode::Portable};
  if (fastCodeAvailable(FastCode::Avx2)) codes.push_back(FastCode::Avx2);
  if (fastCodeAvailable(FastCode::Avx512)) codes.push_back(FastCode::Avx512);
  return codes;
}

// Images that exercise the kernels: smooth texture with shapes, noise over the full range,
// near-black and near-white blocks (saturating differences), and a flat image.
std::vector<cv::Mat> testImages() {
  std::vector<cv::Mat> images{test::texturedImage(203, 131, 3)};
  cv::RNG rng(11);
  cv::Mat noise(97, 150, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  images.push_back(noise);
  cv::Mat extremes(90, 140, CV_8UC1);
  for (int y = 0; y < extremes.rows; ++y)
    for (int x = 0; x < extremes.cols; ++x) {
      const bool dark = ((x / 7) + (y / 5)) % 2 == 0;
      extremes.at<std::uint8_t>(y, x) =
          static_cast<std::uint8_t>(dark ? rng.uniform(0, 12) : rng.uniform(244, 256));
    }
  images.push_back(extremes);
  images.emplace_back(40, 60, CV_8UC1, cv::Scalar(128));
  return images;
}

TEST(FastCorners, WholeImagesMatchOpenCvAtEveryThreshold) {
  for (const FastCode code : availableCodes())
    for (const cv::Mat& image : testImages()) {
      const cv::Rect area(3, 3, image.cols - 6, image.rows - 6);
      for (const int threshold : {0, 1, 7, 20, 40, 100, 200}) {
        const auto expected = openCvCorners(image, area, threshold, image.cols);
        EXPECT_EQ(mapCorners(image, area, threshold, area, threshold, image.cols, code), expected)
            << "code " << static_cast<int>(code) << ", image " << image.cols << "x" << image.rows << ", threshold "
            << threshold;
      }
    }
}

TEST(FastCorners, SubAreasOfALowerThresholdMapMatchOpenCvOnThoseAreas) {
  // As OrbExtractor reads them: one map at the low threshold, areas at either threshold, of
  // any width (narrower and wider than a vector), their last columns dropped.
  const cv::Mat image = test::texturedImage(260, 150, 5, 150);
  const cv::Rect mapArea(19, 19, image.cols - 3 - 19, image.rows - 2 * 19);
  std::size_t nonEmpty = 0;
  for (const FastCode code : availableCodes())
    for (const int width : {1, 5, 15, 16, 17, 31, 32, 33, 48, 100, 200})
      for (const int threshold : {7, 20}) {
        const cv::Rect area(mapArea.x + 11, mapArea.y + 9, std::min(width, mapArea.width - 11), 60);
        for (const int dropped : {0, 1, 9}) {
          const int keepBelowX = area.x + std::max(1, area.width - dropped);
          const auto expected = openCvCorners(image, area, threshold, keepBelowX);
          nonEmpty += expected.empty() ? 0 : 1;
          EXPECT_EQ(mapCorners(image, mapArea, 7, area, threshold, keepBelowX, code), expected)
              << "code " << static_cast<int>(code) << ", width " << width << ", threshold " << threshold
              << ", dropped " << dropped;
        }
      }
  EXPECT_GT(nonEmpty, 20u);  // the areas hold corners, so the comparison means something
}

TEST(FastCorners, VectorCodeWritesThePortableScores) {
  const auto codes = availableCodes();
  if (codes.size() == 1) GTEST_SKIP() << "no vector code on this CPU";
  for (const cv::Mat& image : testImages())
    for (const int width : {image.cols - 6, 130, 64, 63, 40, 31, 16, 9})
      for (const FastCode code : codes) {
        if (width > image.cols - 6) continue;
        const cv::Rect area(3, 3, width, image.rows - 6);
        cv::Mat portable, vector;
        fastScoreMap(image, area, 7, portable, FastCode::Portable);
        fastScoreMap(image, area, 7, vector, code);
        EXPECT_EQ(cv::norm(portable, vector, cv::NORM_INF), 0.0) << "code " << static_cast<int>(code) << ", width " << width;
      }
}

TEST(FastCorners, RejectsAreasWithoutTheCircleContext) {
  const cv::Mat image(40, 40, CV_8UC1, cv::Scalar(0));
  cv::Mat scores;
  EXPECT_THROW(fastScoreMap(image, cv::Rect(2, 3, 10, 10), 7, scores), cv::Exception);
  EXPECT_THROW(fastScoreMap(image, cv::Rect(3, 3, 35, 10), 7, scores), cv::Exception);
  EXPECT_NO_THROW(fastScoreMap(image, cv::Rect(3, 3, 34, 34), 7, scores));
}

}  // namespace
}  // namespace orbis
