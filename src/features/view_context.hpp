// Private to src/features: whether an image is a view with pixels of its parent around it, which
// the vectorised kernels (the blur, the pyramid's resize) read beyond the view's edges.
#pragma once

#include <opencv2/core.hpp>

namespace orbis::detail {

// Whether `m` is a view with `margin` valid pixels of its parent on every side.
inline bool hasContext(const cv::Mat& m, int margin) {
  cv::Size whole;
  cv::Point offset;
  m.locateROI(whole, offset);
  return offset.x >= margin && offset.y >= margin && whole.width - offset.x - m.cols >= margin &&
         whole.height - offset.y - m.rows >= margin;
}

}  // namespace orbis::detail
