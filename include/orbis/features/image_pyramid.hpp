// orbis/features/image_pyramid.hpp — a reusable scale pyramid with readable borders.
//
// Contract: build() converts an 8-bit grey, BGR or BGRA image to grey and resamples it into ScaleLevels::levels() images (level l has
// size round(W/scale[l]) x round(H/scale[l]), each from the previous by bilinear resize, as
// ORB-SLAM does). level(l) is a view of the interior; kBorder pixels around it are valid
// memory filled by reflection (BORDER_REFLECT_101), so patch operations near the image edge
// (orientation, rotated BRIEF, stereo patch correlation) read defined values. Buffers are kept
// between calls: rebuilding at the same image size allocates nothing. build() is allocate(),
// setLevel0Rows() over every row, finishLevel0(), then buildLevel(1), buildLevel(2), ... in
// order; a level may be read on another thread once it is finished (and that is visible there),
// while later levels are built.
#pragma once

#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/features/keypoint.hpp"
#include "orbis/features/linear_resize.hpp"

namespace orbis {

// Maps pixel coordinates between a pyramid level and level 0. cv::resize aligns pixel centres,
// so x0 + 0.5 = (xl + 0.5) * (cols0 / colsl). ORB-SLAM's xl * scale drops the half pixel and
// uses the nominal factor instead of the rounded level size: on 640x480 its keypoints of the
// coarse levels land up to 1.8 px from where the level's image puts them (image_pyramid_test).
struct PyramidLevelMap {
  // Level-0 pixels per level pixel, along x and y.
  float sx = 1.f, sy = 1.f;  // level-0 pixels per level pixel, along x and y

  // The map between two images of a pyramid.
  static PyramidLevelMap between(const cv::Mat& base, const cv::Mat& level) {
    return {static_cast<float>(base.cols) / static_cast<float>(level.cols),
            static_cast<float>(base.rows) / static_cast<float>(level.rows)};
  }
  // @{
  // Between level-0 and level coordinates, pixel centres aligned.
  float toBaseX(float x) const { return (x + 0.5f) * sx - 0.5f; }
  float toBaseY(float y) const { return (y + 0.5f) * sy - 0.5f; }
  float fromBaseX(float x) const { return (x + 0.5f) / sx - 0.5f; }
  float fromBaseY(float y) const { return (y + 0.5f) / sy - 0.5f; }
  // @}
};

// The scaled images of a frame, with a border for the descriptor's patch.
class ImagePyramid {
 public:
  // Border width, pixels.
  static constexpr int kBorder = 19;

  // Builds every level from an 8-bit grey, BGR or BGRA image (converted straight into level 0).
  void build(const cv::Mat& image, const ScaleLevels& levels);
  // @{
  // build() in steps. allocate(): the buffers for an image of `size`. setLevel0Rows(): rows
  // [rowBegin, rowEnd) of level 0 from the image (disjoint row ranges may be set on different
  // threads); finishLevel0(): its border, once every row is set. buildLevel(l), l >= 1: level l
  // from level l - 1, which must be finished.
  void allocate(cv::Size size, const ScaleLevels& levels);
  void setLevel0Rows(const cv::Mat& image, int rowBegin, int rowEnd);
  void finishLevel0();
  void buildLevel(int l);
  // @}
  // @{
  // The levels (without border), one level, all of them, and a level's coordinate map.
  int levels() const { return static_cast<int>(interior_.size()); }
  const cv::Mat& level(int l) const { return interior_[static_cast<std::size_t>(l)]; }
  std::span<const cv::Mat> images() const { return interior_; }
  PyramidLevelMap levelMap(int l) const { return PyramidLevelMap::between(level(0), level(l)); }
  // @}

  // Refills the reflected border of a bordered buffer from its interior.
  static void fillBorder(cv::Mat& bordered, int border);

 private:
  std::vector<cv::Mat> bordered_, interior_;
  std::vector<LinearResizer> resizers_;  // per level: each keeps its sizes' tables
};

}  // namespace orbis
