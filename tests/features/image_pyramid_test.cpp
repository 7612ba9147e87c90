// Pyramid level <-> level-0 pixel mapping: a blob's centroid found on a coarse level maps back
// onto where it is drawn at level 0, which ORB-SLAM's x * scale does not do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "orbis/features/image_pyramid.hpp"

namespace orbis {
namespace {

// Intensity centroid of `image` (background 0).
cv::Point2d centroid(const cv::Mat& image) {
  const cv::Moments m = cv::moments(image);
  return {m.m10 / m.m00, m.m01 / m.m00};
}

TEST(ImagePyramid, LevelMapRoundTripsAndFollowsTheResize) {
  // Blobs near the far corner, where both the dropped half pixel and the rounded level size
  // (640 / 1.2^7 = 178.6 -> 179 columns) weigh most.
  const ScaleLevels levels(8, 1.2f);
  for (const cv::Point2d at : {cv::Point2d(560.3, 400.7), cv::Point2d(80.6, 60.2)}) {
    cv::Mat image(480, 640, CV_8UC1, cv::Scalar(0));
    cv::circle(image, cv::Point(static_cast<int>(at.x * 16), static_cast<int>(at.y * 16)), 6 * 16, cv::Scalar(255),
               cv::FILLED, cv::LINE_AA, 4);
    cv::GaussianBlur(image, image, cv::Size(0, 0), 4.0);
    const cv::Point2d truth = centroid(image);
    ImagePyramid pyramid;
    pyramid.build(image, levels);
    double worstNaive = 0, worstMapped = 0;
    for (int l = 1; l < levels.levels(); ++l) {
      const PyramidLevelMap map = pyramid.levelMap(l);
      const cv::Point2d c = centroid(pyramid.level(l));
      const double u = map.toBaseX(static_cast<float>(c.x)), v = map.toBaseY(static_cast<float>(c.y));
      EXPECT_NEAR(u, truth.x, 0.15) << "level " << l;
      EXPECT_NEAR(v, truth.y, 0.15) << "level " << l;
      EXPECT_NEAR(map.fromBaseX(static_cast<float>(u)), c.x, 1e-3);
      EXPECT_NEAR(map.fromBaseY(static_cast<float>(v)), c.y, 1e-3);
      const double scale = levels.scale[static_cast<std::size_t>(l)];
      worstNaive = std::max({worstNaive, std::abs(c.x * scale - truth.x), std::abs(c.y * scale - truth.y)});
      worstMapped = std::max({worstMapped, std::abs(u - truth.x), std::abs(v - truth.y)});
    }
    std::printf("[ pyramid  ] blob at (%.2f, %.2f), levels 1-7: level map off by at most %.3f px, x * scale by %.3f px\n",
                truth.x, truth.y, worstMapped, worstNaive);
    // The nominal mapping misses by more than a pixel on the coarse levels (half a pixel times
    // the scale, plus the rounded level size).
    EXPECT_GT(worstNaive, 1.0);
  }
}

// A colour image is converted straight into level 0, in one piece or in row ranges: the levels
// equal those of the pyramid of cv::cvtColor's grey image, borders included.
TEST(ImagePyramid, ColourInputEqualsThePyramidOfItsGreyImage) {
  const ScaleLevels levels(8, 1.2f);
  cv::Mat bgr(237, 311, CV_8UC3);
  cv::randu(bgr, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::Mat bgra, grey;
  cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  ImagePyramid reference;
  reference.build(grey, levels);
  ImagePyramid whole, fromBgra, inRows;
  whole.build(bgr, levels);
  fromBgra.build(bgra, levels);
  inRows.allocate(bgr.size(), levels);
  inRows.setLevel0Rows(bgr, 100, bgr.rows);
  inRows.setLevel0Rows(bgr, 0, 100);
  inRows.finishLevel0();
  for (int l = 1; l < levels.levels(); ++l) inRows.buildLevel(l);
  constexpr int b = ImagePyramid::kBorder;
  for (int l = 0; l < levels.levels(); ++l) {
    auto bordered = [&](const ImagePyramid& p) {
      cv::Mat view = p.level(l);
      view.adjustROI(b, b, b, b);
      return view;
    };
    const cv::Mat expected = bordered(reference);
    ASSERT_EQ(expected.size(), cv::Size(reference.level(l).cols + 2 * b, reference.level(l).rows + 2 * b));
    EXPECT_EQ(cv::norm(expected, bordered(whole), cv::NORM_INF), 0.0) << "BGR, level " << l;
    EXPECT_EQ(cv::norm(expected, bordered(fromBgra), cv::NORM_INF), 0.0) << "BGRA, level " << l;
    EXPECT_EQ(cv::norm(expected, bordered(inRows), cv::NORM_INF), 0.0) << "BGR in two row ranges, level " << l;
  }
}

}  // namespace
}  // namespace orbis
