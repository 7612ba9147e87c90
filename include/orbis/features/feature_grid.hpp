// orbis/features/feature_grid.hpp — keypoints bucketed into a fixed grid for area queries.
//
// Contract: build() assigns each keypoint (undistorted positions) to one of kCols x kRows cells
// spanning [minX, maxX) x [minY, maxY) (ORB-SLAM: 64 x 48 over the undistorted image bounds);
// keypoints outside the bounds are left out. featuresInArea(u, v, r, minLevel, maxLevel)
// returns the indices of keypoints with |u' - u| < r and |v' - v| < r (a square window, as
// ORB-SLAM) whose octave lies in [minLevel, maxLevel] (a negative bound means "no bound"),
// in cell order. Storage is two flat arrays; queries into a caller's vector allocate nothing
// once it has grown.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "orbis/features/keypoint.hpp"

namespace orbis {

// Keypoints binned into a 64 × 48 grid over the image, for area queries.
class FeatureGrid {
 public:
  // @{
  // Grid size.
  static constexpr int kCols = 64;
  static constexpr int kRows = 48;
  // @}

  // Allocates and writes the storage for `keypoints` keypoints, so that a later build() of as
  // many reuses it (features/feature_storage.hpp prepares frames' storage this way).
  void reserve(std::size_t keypoints) {
    cellStart_.assign(kCols * kRows + 1, 0);
    entries_.resize(keypoints);
    entries_.clear();
  }

  // Bins keypoints over the undistorted image bounds [minX, maxX) × [minY, maxY).
  void build(std::span<const Keypoint> keypoints, float minX, float maxX, float minY, float maxY) {
    minX_ = minX;
    minY_ = minY;
    maxX_ = maxX;
    maxY_ = maxY;
    invCellW_ = static_cast<float>(kCols) / std::max(maxX - minX, 1e-3f);
    invCellH_ = static_cast<float>(kRows) / std::max(maxY - minY, 1e-3f);
    cellStart_.assign(kCols * kRows + 1, 0);
    std::vector<int> cellOfKeypoint(keypoints.size(), -1);
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      const int c = cellIndex(keypoints[i].u, keypoints[i].v);
      cellOfKeypoint[i] = c;
      if (c >= 0) ++cellStart_[static_cast<std::size_t>(c) + 1];
    }
    for (std::size_t c = 0; c < kCols * kRows; ++c) cellStart_[c + 1] += cellStart_[c];
    entries_.resize(static_cast<std::size_t>(cellStart_.back()));
    std::vector<int> fill(cellStart_.begin(), cellStart_.end() - 1);
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      const int c = cellOfKeypoint[i];
      if (c < 0) continue;
      entries_[static_cast<std::size_t>(fill[static_cast<std::size_t>(c)]++)] = {
          keypoints[i].u, keypoints[i].v, static_cast<int>(i), keypoints[i].octave};
    }
  }

  // Calls visit(index, octave) for each keypoint within radius r of (u, v) whose level lies in
  // [minLevel, maxLevel] (−1: any), in cell order: featuresInArea without the list.
  template <class Visit>
  void forEachInArea(float u, float v, float r, int minLevel, int maxLevel, Visit&& visit) const {
    if (entries_.empty()) return;
    const int c0 = std::max(0, static_cast<int>(std::floor((u - r - minX_) * invCellW_)));
    const int c1 = std::min(kCols - 1, static_cast<int>(std::floor((u + r - minX_) * invCellW_)));
    const int r0 = std::max(0, static_cast<int>(std::floor((v - r - minY_) * invCellH_)));
    const int r1 = std::min(kRows - 1, static_cast<int>(std::floor((v + r - minY_) * invCellH_)));
    for (int row = r0; row <= r1; ++row) {
      for (int col = c0; col <= c1; ++col) {
        const auto cell = static_cast<std::size_t>(row * kCols + col);
        for (int e = cellStart_[cell]; e < cellStart_[cell + 1]; ++e) {
          const Entry& k = entries_[static_cast<std::size_t>(e)];
          if (minLevel >= 0 && k.octave < minLevel) continue;
          if (maxLevel >= 0 && k.octave > maxLevel) continue;
          if (std::abs(k.u - u) < r && std::abs(k.v - v) < r) visit(k.index, k.octave);
        }
      }
    }
  }

  // Appends the keypoints within radius r of (u, v) whose level lies in [minLevel, maxLevel] (−1:
  // any).
  void featuresInArea(float u, float v, float r, int minLevel, int maxLevel, std::vector<int>& out) const {
    out.clear();
    forEachInArea(u, v, r, minLevel, maxLevel, [&](int index, int) { out.push_back(index); });
  }

  // The keypoints within radius r of (u, v) whose level lies in [minLevel, maxLevel] (−1: any).
  std::vector<int> featuresInArea(float u, float v, float r, int minLevel = -1, int maxLevel = -1) const {
    std::vector<int> out;
    featuresInArea(u, v, r, minLevel, maxLevel, out);
    return out;
  }

  // Cell of a position, or -1 outside the bounds.
  int cellIndex(float u, float v) const {
    const float cx = std::floor((u - minX_) * invCellW_), cy = std::floor((v - minY_) * invCellH_);
    if (!(cx >= 0.f && cx < kCols && cy >= 0.f && cy < kRows)) return -1;
    return static_cast<int>(cy) * kCols + static_cast<int>(cx);
  }
  // Whether (u, v) lies inside the bounds.
  bool inBounds(float u, float v) const { return u >= minX_ && u < maxX_ && v >= minY_ && v < maxY_; }
  // @{
  // The bounds.
  float minX() const { return minX_; }
  float maxX() const { return maxX_; }
  float minY() const { return minY_; }
  float maxY() const { return maxY_; }
  // @}
  // Keypoints in a cell.
  int cellCount(int cell) const {
    return cellStart_.empty() ? 0 : cellStart_[static_cast<std::size_t>(cell) + 1] - cellStart_[static_cast<std::size_t>(cell)];
  }

 private:
  struct Entry {
    float u, v;
    int index, octave;
  };
  float minX_ = 0, minY_ = 0, maxX_ = 0, maxY_ = 0, invCellW_ = 0, invCellH_ = 0;
  std::vector<int> cellStart_;
  std::vector<Entry> entries_;
};

}  // namespace orbis
