// orbis/synth/texture.hpp — mip-mapped grey textures for the synthetic renderer.
//
// Contract: a Texture is a float image (grey levels 0..255) with a full mip chain built by
// exact 2x2 box averaging, so texel centres of every level line up with level 0 (no drift of
// half a texel between levels of detail: a linear ramp samples the same at every level). Texel (i, j) of level 0 covers the
// texture coordinates [i, i+1) x [j, j+1); sample() takes level-0 coordinates and clamps at
// the border. Sampling never allocates and never throws (it is the renderer's inner loop).
// makeCornerTexture() paints a "dead leaves" pattern of random rectangles at many scales over
// multi-octave value noise: corners at every scale, deterministic from the seed.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace orbis::synth {

// A grey texture with its mip levels.
class Texture {
 public:
  Texture() = default;
  // image: CV_32FC1 (any other depth is converted); dimensions need not be powers of two.
  explicit Texture(const cv::Mat& image);

  // @{
  // Size of level 0, number of levels, and one level.
  int width() const { return levels_.empty() ? 0 : levels_[0].cols; }
  int height() const { return levels_.empty() ? 0 : levels_[0].rows; }
  int levelCount() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int l) const { return levels_[static_cast<std::size_t>(l)]; }
  // @}

  // Trilinear sample at level-0 texture coordinates (x, y); lod = log2(texels per sample).
  float sample(double x, double y, double lod) const {
    if (lod <= 0.0) return bilinear(0, x, y);
    const int maxLevel = levelCount() - 1;
    const int l0 = static_cast<int>(lod);
    if (l0 >= maxLevel) return bilinear(maxLevel, x, y);
    const float f = static_cast<float>(lod - l0);
    const float a = bilinear(l0, x, y);
    const float b = bilinear(l0 + 1, x, y);
    return a + f * (b - a);
  }

  // Bilinear sample of level l at level-0 coordinates (x, y).
  float bilinear(int l, double x, double y) const {
    const cv::Mat& m = levels_[static_cast<std::size_t>(l)];
    const double s = scale_[static_cast<std::size_t>(l)];
    // Texel centres sit at half-integers, hence the -0.5.
    const double xs = x * s - 0.5, ys = y * s - 0.5;
    const double xf = std::floor(xs), yf = std::floor(ys);
    const float fx = static_cast<float>(xs - xf), fy = static_cast<float>(ys - yf);
    const int x0 = clampInt(static_cast<int>(xf), m.cols), x1 = clampInt(static_cast<int>(xf) + 1, m.cols);
    const int y0 = clampInt(static_cast<int>(yf), m.rows), y1 = clampInt(static_cast<int>(yf) + 1, m.rows);
    const float* r0 = m.ptr<float>(y0);
    const float* r1 = m.ptr<float>(y1);
    const float top = r0[x0] + fx * (r0[x1] - r0[x0]);
    const float bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
    return top + fy * (bottom - top);
  }

 private:
  static int clampInt(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }
  std::vector<cv::Mat> levels_;
  std::vector<double> scale_;  // level size / level-0 size, per axis (exact powers of 1/2)
};

// The random corner-rich textures of the rendered scenes: nested rectangles over many scales.
struct CornerTextureParams {
  int smallestLeaf = 5;     // texels: edge of the smallest rectangles
  int largestLeaf = 240;    // texels: edge of the largest rectangles
  double largeCoverage = 0.6;   // fraction of the area each of the large scales covers
  double smallCoverage = 0.17;  // the same for scales below a third of the largest
  double noiseAmplitude = 18.0;  // grey levels of the value noise under the rectangles
};

// width x height texels; grey levels in [0, 255].
cv::Mat makeCornerTexture(int width, int height, std::uint64_t seed,
                          const CornerTextureParams& params = {});

}  // namespace orbis::synth
