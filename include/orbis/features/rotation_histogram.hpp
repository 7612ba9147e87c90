// orbis/features/rotation_histogram.hpp — rotation-consistency check for a set of matches.
//
// Contract: add(angleDifferenceDeg, item) files a match by the difference of its two keypoint
// orientations into one of kBins bins of 360/kBins degrees, centred on multiples of the bin
// width (so "no rotation" sits mid-bin rather than on the edge between the first and last
// bins, where noise would split it in two); rejected() lists the items outside
// the three most populated bins (the second and third count only when they hold at least a
// tenth of the first; ORB-SLAM's rule). A consistent image rotation puts the true matches in
// one or two neighbouring bins, so what is rejected is mostly wrong. Reusable after clear().
#pragma once

#include <array>
#include <cmath>
#include <vector>

namespace orbis {

// ORB-SLAM's orientation consistency check: matches binned by their keypoints' angle difference;
// only the three fullest bins are kept.
class RotationHistogram {
 public:
  // Bins over 360°.
  static constexpr int kBins = 30;

  // Empties the bins.
  void clear() {
    for (auto& b : bins_) b.clear();
  }

  // Adds a match by its angle difference.
  void add(float angleDifferenceDeg, int item) {
    float a = std::fmod(angleDifferenceDeg, 360.f);
    if (a < 0.f) a += 360.f;
    int bin = static_cast<int>(std::lround(a * (static_cast<float>(kBins) / 360.f)));
    if (bin >= kBins) bin -= kBins;
    bins_[static_cast<std::size_t>(bin)].push_back(item);
  }

  // Nulls the slots (indexed by item) of the rejected items; returns how many held something.
  template <class Slots>
  int clearRejected(Slots& slots) const {
    std::vector<int> drop;
    rejected(drop);
    int cleared = 0;
    for (int i : drop) {
      auto& slot = slots[static_cast<std::size_t>(i)];
      if (slot) ++cleared;
      slot = nullptr;
    }
    return cleared;
  }

  // Items to drop, appended to `out` (which is not cleared).
  void rejected(std::vector<int>& out) const {
    int first = -1, second = -1, third = -1;
    auto size = [this](int b) { return b < 0 ? 0 : static_cast<int>(bins_[static_cast<std::size_t>(b)].size()); };
    for (int b = 0; b < kBins; ++b) {
      const int n = size(b);
      if (n > size(first)) {
        third = second;
        second = first;
        first = b;
      } else if (n > size(second)) {
        third = second;
        second = b;
      } else if (n > size(third)) {
        third = b;
      }
    }
    const float minKept = 0.1f * static_cast<float>(size(first));
    if (static_cast<float>(size(second)) < minKept) second = third = -1;
    else if (static_cast<float>(size(third)) < minKept) third = -1;
    for (int b = 0; b < kBins; ++b) {
      if (b == first || b == second || b == third) continue;
      const auto& items = bins_[static_cast<std::size_t>(b)];
      out.insert(out.end(), items.begin(), items.end());
    }
  }

 private:
  std::array<std::vector<int>, kBins> bins_;
};

}  // namespace orbis
