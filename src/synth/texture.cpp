#include "orbis/synth/texture.hpp"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "orbis/synth/rng.hpp"

namespace orbis::synth {

namespace {

constexpr int kMaxLevels = 9;

// Exact 2x2 box average; the source has even dimensions by construction.
cv::Mat halve(const cv::Mat& src) {
  cv::Mat dst(src.rows / 2, src.cols / 2, CV_32FC1);
  for (int y = 0; y < dst.rows; ++y) {
    const float* a = src.ptr<float>(2 * y);
    const float* b = src.ptr<float>(2 * y + 1);
    float* d = dst.ptr<float>(y);
    for (int x = 0; x < dst.cols; ++x)
      d[x] = 0.25f * (a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1]);
  }
  return dst;
}

// Value noise: random values on a coarse lattice, bicubically interpolated.
void addValueNoise(cv::Mat& image, int cell, double amplitude, SynthRng& rng) {
  const int gw = image.cols / cell + 3, gh = image.rows / cell + 3;
  cv::Mat grid(gh, gw, CV_32FC1);
  for (int y = 0; y < gh; ++y)
    for (int x = 0; x < gw; ++x) grid.at<float>(y, x) = static_cast<float>(rng.uniform(-amplitude, amplitude));
  cv::Mat up;
  cv::resize(grid, up, cv::Size(gw * cell, gh * cell), 0, 0, cv::INTER_CUBIC);
  image += up(cv::Rect(cell, cell, image.cols, image.rows));
}

}  // namespace

Texture::Texture(const cv::Mat& image) {
  cv::Mat base;
  image.convertTo(base, CV_32FC1);
  int levels = 1;
  while (levels < kMaxLevels && std::min(base.cols, base.rows) >> levels >= 2) ++levels;
  // Pad right and bottom (replicating the border) so every level halves exactly: the padding
  // lies outside [0, width) x [0, height), so coordinates are unchanged.
  const int m = 1 << (levels - 1);
  const int padW = (m - base.cols % m) % m, padH = (m - base.rows % m) % m;
  if (padW || padH) cv::copyMakeBorder(base, base, 0, padH, 0, padW, cv::BORDER_REPLICATE);
  levels_.push_back(base);
  scale_.push_back(1.0);
  for (int l = 1; l < levels; ++l) {
    levels_.push_back(halve(levels_.back()));
    scale_.push_back(scale_.back() * 0.5);
  }
}

cv::Mat makeCornerTexture(int width, int height, std::uint64_t seed, const CornerTextureParams& params) {
  SynthRng rng(seed);
  cv::Mat image(height, width, CV_32FC1, cv::Scalar(128.0));
  addValueNoise(image, 256, 2.0 * params.noiseAmplitude, rng);
  addValueNoise(image, 48, params.noiseAmplitude, rng);
  addValueNoise(image, 12, 0.5 * params.noiseAmplitude, rng);
  const double area = static_cast<double>(width) * height;
  // Largest first, so smaller leaves land on top: every scale keeps visible corners.
  for (int size = params.largestLeaf; size >= params.smallestLeaf; size = size * 2 / 3) {
    // Sparser small leaves, so the large shapes (corners for the coarse pyramid levels) stay.
    const double coverage = size * 3 >= params.largestLeaf ? params.largeCoverage : params.smallCoverage;
    const auto count = static_cast<long>(coverage * area / (1.5 * size * 1.5 * size));
    for (long i = 0; i < count; ++i) {
      const int w = rng.uniformInt(size, 2 * size), h = rng.uniformInt(size, 2 * size);
      const int x = rng.uniformInt(-w / 2, width - w / 2), y = rng.uniformInt(-h / 2, height - h / 2);
      // Contrast against what lies underneath, so the new corners are strong.
      const int cx = std::clamp(x + w / 2, 0, width - 1), cy = std::clamp(y + h / 2, 0, height - 1);
      const double under = image.at<float>(cy, cx);
      double value = under + (rng.uniform() < 0.5 ? -1.0 : 1.0) * rng.uniform(60.0, 140.0);
      if (value < 10.0 || value > 245.0) value = under < 128.0 ? under + rng.uniform(60.0, 110.0)
                                                               : under - rng.uniform(60.0, 110.0);
      cv::rectangle(image, cv::Rect(x, y, w, h), cv::Scalar(std::clamp(value, 0.0, 255.0)), cv::FILLED);
    }
    if (size * 2 / 3 == size) break;
  }
  cv::min(cv::max(image, 0.0), 255.0, image);
  return image;
}

}  // namespace orbis::synth
