// Scale pyramid with reflected borders; see include/orbis/features/image_pyramid.hpp.
#include "orbis/features/image_pyramid.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <opencv2/imgproc.hpp>

namespace orbis {

void ImagePyramid::fillBorder(cv::Mat& bordered, int border) {
  const int w = bordered.cols - 2 * border;
  const int h = bordered.rows - 2 * border;
  if (w <= border || h <= border) {
    // Too small to reflect in place; a copy through copyMakeBorder is rare and cheap here.
    cv::Mat inner = bordered(cv::Rect(border, border, w, h)).clone();
    cv::copyMakeBorder(inner, bordered, border, border, border, border, cv::BORDER_REPLICATE);
    return;
  }
  for (int r = border; r < border + h; ++r) {
    std::uint8_t* p = bordered.ptr<std::uint8_t>(r);
    for (int k = 1; k <= border; ++k) {
      p[border - k] = p[border + k];
      p[border + w - 1 + k] = p[border + w - 1 - k];
    }
  }
  const auto rowBytes = static_cast<std::size_t>(bordered.cols);
  for (int k = 1; k <= border; ++k) {
    std::memcpy(bordered.ptr(border - k), bordered.ptr(border + k), rowBytes);
    std::memcpy(bordered.ptr(border + h - 1 + k), bordered.ptr(border + h - 1 - k), rowBytes);
  }
}

void ImagePyramid::build(const cv::Mat& image, const ScaleLevels& levels) {
  allocate(image.size(), levels);
  setLevel0Rows(image, 0, image.rows);
  finishLevel0();
  for (int l = 1; l < this->levels(); ++l) buildLevel(l);
}

void ImagePyramid::allocate(cv::Size size0, const ScaleLevels& levels) {
  const auto n = static_cast<std::size_t>(levels.levels());
  bordered_.resize(n);
  interior_.resize(n);
  resizers_.resize(n);
  for (std::size_t l = 0; l < n; ++l) {
    // At least one pixel, so tiny inputs give tiny levels rather than an OpenCV assertion.
    const cv::Size size(std::max(1, static_cast<int>(std::lround(size0.width * levels.invScale[l]))),
                        std::max(1, static_cast<int>(std::lround(size0.height * levels.invScale[l]))));
    bordered_[l].create(size.height + 2 * kBorder, size.width + 2 * kBorder, CV_8UC1);
    interior_[l] = bordered_[l](cv::Rect(kBorder, kBorder, size.width, size.height));
  }
}

void ImagePyramid::buildLevel(int l) {
  CV_Assert(l >= 1 && l < levels());
  const auto i = static_cast<std::size_t>(l);
  resizers_[i].resize(interior_[i - 1], interior_[i]);  // cv::resize's bits (linear_resize.hpp)
  fillBorder(bordered_[i], kBorder);
}

void ImagePyramid::setLevel0Rows(const cv::Mat& image, int rowBegin, int rowEnd) {
  CV_Assert(image.size() == interior_[0].size() && 0 <= rowBegin && rowBegin <= rowEnd && rowEnd <= image.rows);
  if (rowBegin == rowEnd) return;
  const cv::Mat source = image.rowRange(rowBegin, rowEnd);
  cv::Mat target = interior_[0].rowRange(rowBegin, rowEnd);  // a view: written in place
  switch (image.type()) {
    case CV_8UC1: source.copyTo(target); break;
    case CV_8UC3: cv::cvtColor(source, target, cv::COLOR_BGR2GRAY); break;
    case CV_8UC4: cv::cvtColor(source, target, cv::COLOR_BGRA2GRAY); break;
    default: CV_Error(cv::Error::StsUnsupportedFormat, "ImagePyramid: expected an 8-bit grey, BGR or BGRA image");
  }
  CV_Assert(target.data == interior_[0].ptr(rowBegin));  // not reallocated
}

void ImagePyramid::finishLevel0() { fillBorder(bordered_[0], kBorder); }

}  // namespace orbis
