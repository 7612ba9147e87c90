// orbis/features/image_pyramid.hpp — a reusable scale pyramid with readable borders.
//
// Contract: build() resamples a gray 8-bit image into ScaleLevels::levels() images (level l has
// size round(W/scale[l]) x round(H/scale[l]), each from the previous by bilinear resize, as
// ORB-SLAM does). level(l) is a view of the interior; kBorder pixels around it are valid
// memory filled by reflection (BORDER_REFLECT_101), so patch operations near the image edge
// (orientation, rotated BRIEF, stereo patch correlation) read defined values. Buffers are kept
// between calls: rebuilding at the same image size allocates nothing.
#pragma once

#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/features/keypoint.hpp"

namespace orbis {

class ImagePyramid {
 public:
  static constexpr int kBorder = 19;

  void build(const cv::Mat& gray8u, const ScaleLevels& levels);
  int levels() const { return static_cast<int>(interior_.size()); }
  const cv::Mat& level(int l) const { return interior_[static_cast<std::size_t>(l)]; }
  std::span<const cv::Mat> images() const { return interior_; }

  // Refills the reflected border of a bordered buffer from its interior.
  static void fillBorder(cv::Mat& bordered, int border);

 private:
  std::vector<cv::Mat> bordered_, interior_;
};

}  // namespace orbis
