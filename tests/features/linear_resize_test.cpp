// LinearResizer against cv::resize(INTER_LINEAR), bit for bit: random sizes and factors, the
// pyramid's chain of levels, and the inputs it hands to cv::resize. Where this CPU has AVX2 the
// test also requires that orbis's own code ran, so it cannot pass by calling cv::resize alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "features/feature_test_util.hpp"
#include "orbis/features/image_pyramid.hpp"
#include "orbis/features/linear_resize.hpp"

namespace orbis {
namespace {

bool cpuRunsAvx2() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

// A w x h view with `margin` pixels of its parent on every side, filled with noise or texture.
cv::Mat viewWithMargin(cv::RNG& rng, int w, int h, int margin, bool smooth) {
  cv::Mat parent(h + 2 * margin, w + 2 * margin, CV_8UC1);
  rng.fill(parent, cv::RNG::UNIFORM, 0, 256);
  if (smooth) cv::GaussianBlur(parent, parent, cv::Size(0, 0), 2.0);
  return parent(cv::Rect(margin, margin, w, h));
}

TEST(LinearResize, GivesCvResizesBitsAtAnySizeAndFactor) {
  if (cpuRunsAvx2()) EXPECT_TRUE(LinearResizer::ownCodeAvailable()) << "this OpenCV rounds differently";
  cv::RNG rng(31);
  LinearResizer resizer;
  int ownRuns = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const int w = rng.uniform(16, 1300), h = rng.uniform(2, 400);
    const double factor = trial % 2 ? 1.2 : std::pow(1.2, rng.uniform(1, 8)) * rng.uniform(0.9, 1.1);
    const cv::Size size(std::max(16, static_cast<int>(std::lround(w / factor))), std::max(1, static_cast<int>(std::lround(h / factor))));
    const cv::Mat src = viewWithMargin(rng, w, h, 16, trial % 3 == 0);
    cv::Mat expected, ours(size, CV_8UC1, cv::Scalar(7));
    cv::resize(src, expected, size, 0, 0, cv::INTER_LINEAR);
    resizer.resize(src, ours);
    if (trial % 2) ownRuns += resizer.lastRanOwnCode();  // the pyramid's factor always runs orbis's code
    ASSERT_EQ(cv::norm(ours, expected, cv::NORM_INF), 0.0) << w << "x" << h << " -> " << size.width << "x" << size.height;
  }
  if (LinearResizer::ownCodeAvailable()) EXPECT_EQ(ownRuns, 75);
}

TEST(LinearResize, PyramidLevelsAreCvResizesChain) {
  const ScaleLevels levels(8, 1.2f);
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(1226, 370), cv::Size(752, 480)}) {
    const cv::Mat image = test::texturedImage(size.width, size.height, 5, 150);
    ImagePyramid pyramid;
    pyramid.build(image, levels);
    pyramid.build(image, levels);  // again, with the tables kept
    cv::Mat previous = image;
    for (int l = 1; l < levels.levels(); ++l) {
      cv::Mat expected;
      cv::resize(previous, expected, pyramid.level(l).size(), 0, 0, cv::INTER_LINEAR);
      ASSERT_EQ(cv::norm(pyramid.level(l), expected, cv::NORM_INF), 0.0) << size << " level " << l;
      previous = expected;
    }
  }
}

TEST(LinearResize, HandsOtherInputsToCvResize) {
  cv::RNG rng(4);
  LinearResizer resizer;
  // A whole image (nothing readable around it), a narrow output, a view with too narrow a margin
  // for the 16 bytes read from a row's last group.
  cv::Mat whole(90, 200, CV_8UC1);
  rng.fill(whole, cv::RNG::UNIFORM, 0, 256);
  const cv::Mat inputs[] = {whole, viewWithMargin(rng, 200, 90, 16, false), viewWithMargin(rng, 200, 90, 8, false)};
  const cv::Size sizes[] = {cv::Size(167, 75), cv::Size(15, 75), cv::Size(167, 75)};
  for (int k = 0; k < 3; ++k) {
    cv::Mat expected, ours(sizes[k], CV_8UC1);
    cv::resize(inputs[k], expected, sizes[k], 0, 0, cv::INTER_LINEAR);
    resizer.resize(inputs[k], ours);
    EXPECT_FALSE(resizer.lastRanOwnCode()) << k;
    EXPECT_EQ(cv::norm(ours, expected, cv::NORM_INF), 0.0) << k;
  }
}

}  // namespace
}  // namespace orbis
