// orbis/features/keypoint.hpp — the keypoint type and the per-level scale tables of a pyramid.
//
// Contract: Keypoint is a plain 20-byte value, not cv::KeyPoint: (u, v) are pixels in the
// level-0 (full-resolution) image, angle is the intensity-centroid orientation in degrees
// [0, 360), response the detector score (FAST score for OrbExtractor), octave the pyramid
// level it was detected on. ScaleLevels holds, per level l, scale = factor^l, its inverse,
// sigma2 = scale^2 (the variance of a measurement at that level, in level-0 pixels^2) and
// its inverse; every extractor and FrameFeatures carries one.
#pragma once

#include <cmath>
#include <vector>

#include <opencv2/core/types.hpp>

namespace orbis {

// A detected keypoint.
struct Keypoint {
  // @{
  // Pixel coordinates.
  float u = 0.f, v = 0.f;
  // @}
  float angle = 0.f;     // degrees, [0, 360)
  float response = 0.f;  // detector score; larger is stronger
  int octave = 0;        // pyramid level
};

// As an OpenCV keypoint.
inline cv::KeyPoint toCvKeyPoint(const Keypoint& k, float size = 31.f) {
  return {k.u, k.v, size, k.angle, k.response, k.octave};
}
// From an OpenCV keypoint.
inline Keypoint fromCvKeyPoint(const cv::KeyPoint& k) {
  return {k.pt.x, k.pt.y, k.angle, k.response, k.octave};
}

// Per pyramid level: scale, its inverse, σ² of a keypoint's position and its inverse.
struct ScaleLevels {
  // @{
  // Per-level values.
  std::vector<float> scale, invScale, sigma2, invSigma2;
  // @}

  ScaleLevels() : ScaleLevels(1, 1.f) {}
  // levels levels, each factor times the previous.
  ScaleLevels(int levels, float factor) {
    const auto n = static_cast<std::size_t>(levels < 1 ? 1 : levels);
    scale.resize(n);
    invScale.resize(n);
    sigma2.resize(n);
    invSigma2.resize(n);
    float s = 1.f;
    for (std::size_t l = 0; l < n; ++l, s *= factor) {
      scale[l] = s;
      invScale[l] = 1.f / s;
      sigma2[l] = s * s;
      invSigma2[l] = 1.f / (s * s);
    }
  }
  // Number of levels.
  int levels() const { return static_cast<int>(scale.size()); }
  // Scale ratio between levels.
  float factor() const { return scale.size() > 1 ? scale[1] : 1.f; }
  // log(ratio)/log(factor): used to predict the level at which a point of a given distance
  // is seen (ORB-SLAM's PredictScale).
  float logFactor() const { return std::log(factor()); }
};

}  // namespace orbis
