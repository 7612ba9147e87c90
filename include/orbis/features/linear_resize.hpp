// orbis/features/linear_resize.hpp — the pyramid's bilinear resize of 8-bit grey images: the
// bits of cv::resize(INTER_LINEAR), in less time.
//
// Contract: LinearResizer::resize(src, dst) writes into dst (8-bit grey, already sized; may be a
// view) exactly what cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_LINEAR) writes for an
// 8-bit grey src. Its own code (AVX2) runs where the CPU has AVX2, dst is at least 16 pixels
// wide, src is less than about 1.75 times dst's width (the pyramid's factor is 1.2) and is a view
// with 16 pixels of its parent on every side (the pyramid's bordered levels have 19), and only once a check at first use found it equal to this
// process's cv::resize on test images: OpenCV's fixed-point rounding is its build's, and any
// other build keeps cv::resize. Everywhere else cv::resize runs. The coefficient tables for a
// pair of sizes are kept between calls. One resizer per thread (the pyramid keeps one per
// level). Design and figures: docs/notes/2026-11-28-speed-resize.md.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace orbis {

// cv::resize(INTER_LINEAR) of 8-bit grey images, computed by orbis where it can be.
class LinearResizer {
 public:
  // dst = cv::resize(src, dst.size(), INTER_LINEAR), bit for bit; dst must be CV_8UC1 and sized.
  void resize(const cv::Mat& src, cv::Mat& dst);
  // Whether the last resize() ran orbis's own code (false: it called cv::resize).
  bool lastRanOwnCode() const { return lastOwn_; }
  // Whether this process runs orbis's own code where the inputs allow it (AVX2, and the check
  // at first use passed).
  static bool ownCodeAvailable();

 private:
  void prepare(cv::Size src, cv::Size dst);
  void resizeWithOwnCode(const cv::Mat& src, cv::Mat& dst);
  const std::int16_t* horizontalRow(const cv::Mat& src, int y, int keep);

  cv::Size srcSize_, dstSize_;
  std::vector<int> xOffsets_, yOffsets_;          // first source column / row of each output
  std::vector<std::int16_t> xTaps_, yTaps_;        // their two weights, 2048 = 1
  std::vector<int> groupFirst_;                    // per 8 outputs: the first source column read
  std::vector<std::uint8_t> groupMasks_;           // per 8 outputs: the byte shuffle into pairs
  bool shuffleFits_ = false;                       // every group's columns within 16 bytes
  std::vector<std::int16_t> rows_[2];              // horizontally resized source rows, >> 4
  int rowOf_[2] = {-1, -1};                        // which source row each holds
  bool lastOwn_ = false;
};

}  // namespace orbis
