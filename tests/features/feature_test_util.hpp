// tests/features/feature_test_util.hpp — images for the feature tests: a seeded synthetic
// texture (no data needed) and frames read from the shared datasets.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace orbis::test {

// Random shapes of random grey levels over a random-noise background, lightly blurred: corners
// everywhere, at many scales. Same seed, same image.
inline cv::Mat texturedImage(int width, int height, std::uint64_t seed, int pixelsPerShape = 600) {
  cv::RNG rng(seed);
  cv::Mat img(height, width, CV_8UC1);
  rng.fill(img, cv::RNG::UNIFORM, 60, 200);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 4.0);
  const int shapes = width * height / pixelsPerShape;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, width), rng.uniform(0, height));
    const int size = rng.uniform(3, 28);
    const cv::Scalar grey(rng.uniform(0, 256));
    switch (rng.uniform(0, 3)) {
      case 0:
        cv::rectangle(img, c, c + cv::Point(size, rng.uniform(3, 28)), grey, cv::FILLED);
        break;
      case 1:
        cv::circle(img, c, size / 2 + 1, grey, cv::FILLED, cv::LINE_AA);
        break;
      default: {
        const cv::Point pts[3] = {c, c + cv::Point(size, rng.uniform(-size, size)),
                                  c + cv::Point(rng.uniform(-size, size), size)};
        cv::fillConvexPoly(img, pts, 3, grey, cv::LINE_AA);
      }
    }
  }
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  return img;
}

inline std::vector<std::filesystem::path> sortedPngs(const std::filesystem::path& dir, std::size_t count) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".png") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  if (files.size() > count) files.resize(count);
  return files;
}

inline cv::Mat readGray(const std::filesystem::path& p) { return cv::imread(p.string(), cv::IMREAD_GRAYSCALE); }

}  // namespace orbis::test
