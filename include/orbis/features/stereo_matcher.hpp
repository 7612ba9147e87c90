// orbis/features/stereo_matcher.hpp — stereo keypoints from a rectified pair (paper Sec. III-A).
//
// Contract: for every left keypoint, the right keypoints in its row band (+-2 x the scale of
// the right keypoint's level) with octave within one of the left's and disparity in
// [0, bf / minDepth] are candidates; the one at the smallest Hamming distance, if below
// kMaxDescriptorDistance, is refined by sliding an 11x11 patch (+-5 px, on the left keypoint's
// pyramid level, each patch minus its own mean intensity, sum of absolute differences) and a
// parabola through the three best costs; matches at the edge of the slide or with a parabola
// offset beyond one pixel are dropped, and finally those whose patch cost exceeds
// 1.5 x 1.4 x the median cost. Output per left keypoint: uRight (level-0 pixels) and
// depth = bf / disparity, both -1 when unmatched. Images must be rectified: epipolar lines are
// rows. The pyramids are the extractors' (ImagePyramid: interior views with readable border).
// Deterministic; buffers are reused between calls, so one matcher per thread. With
// setParallel(true) the left keypoints are shared with a helper thread the matcher keeps (each
// keypoint's match depends on it alone: the output is bit-identical to the serial one).
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/keypoint.hpp"
#include "orbis/util/helper_thread.hpp"

namespace orbis {

// One image of a stereo pair: its keypoints, descriptors and pyramid.
struct StereoView {
  // @{
  // Keypoints, descriptors and pyramid levels.
  std::span<const Keypoint> keypoints;
  std::span<const OrbDescriptor> descriptors;
  std::span<const cv::Mat> pyramid;
  // @}
};

// ORB-SLAM2's stereo matching along rows: descriptor match, then an 11×11 patch slid along the row
// (zero-mean SAD) and a parabola fit, then outliers by median distance.
class StereoMatcher {
 public:
  // ORB-SLAM2: (TH_HIGH + TH_LOW) / 2.
  static constexpr int kMaxDescriptorDistance = 75;
  static constexpr int kPatchHalf = 5;   // 11x11 correlation window
  static constexpr int kSlide = 5;       // +-5 px search around the descriptor match
  static constexpr float kRowBand = 2.f; // row tolerance, times the right keypoint's scale
  // Matches whose patch cost exceeds this × the median are dropped.
  static constexpr float kOutlierFactor = 1.5f * 1.4f;
  // Fewer left keypoints than this are matched on one thread: waking a helper would cost more.
  static constexpr std::size_t kMinKeypointsForTwoThreads = 128;

  // bf = focal length x baseline (pixels x metres); minDepth bounds the disparity (ORB-SLAM:
  // the baseline, so disparities up to fx).
  void match(const StereoView& left, const StereoView& right, const ScaleLevels& scales, float bf,
             float minDepth, std::vector<float>& uRight, std::vector<float>& depth);

  // Match on two threads (the same output either way).
  void setParallel(bool on) { parallel_ = on; }

 private:
  void indexRightRows(const StereoView& right, const ScaleLevels& scales, int rows);
  int bestRightCandidate(const StereoView& left, const StereoView& right, std::size_t iL, float maxDisparity) const;
  void matchOne(const StereoView& left, const StereoView& right, float bf, float maxDisparity, std::size_t iL,
                std::vector<float>& uRight, std::vector<float>& depth);

  int rows_ = 0;
  std::vector<int> rowStart_, rowEntries_, rowFill_;
  std::vector<int> cost_;  // per left keypoint: its patch cost, -1 when unmatched
  std::vector<std::pair<int, int>> costAndIndex_;
  bool parallel_ = false;
  std::unique_ptr<HelperThread> helper_;
};

}  // namespace orbis
