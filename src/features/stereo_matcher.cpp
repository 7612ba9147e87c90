// Stereo keypoint matching on rectified pairs; see include/orbis/features/stereo_matcher.hpp.
#include "orbis/features/stereo_matcher.hpp"

#include "orbis/features/image_pyramid.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <memory>

namespace orbis {
namespace {

constexpr int kPatchArea = (2 * StereoMatcher::kPatchHalf + 1) * (2 * StereoMatcher::kPatchHalf + 1);

// Sum of the (2h+1) intensities of column x of rows -h..h around row pointer p.
int columnSum(const std::uint8_t* p, int step, int x) {
  int sum = 0;
  for (int dy = -StereoMatcher::kPatchHalf; dy <= StereoMatcher::kPatchHalf; ++dy) sum += p[dy * step + x];
  return sum;
}

// Sum of absolute differences of two patches, each taken relative to its own mean so that a
// brightness offset between the cameras does not count; in units of 1/kPatchArea grey levels,
// which keeps it exact in integers. offset = kPatchArea x (mean of a - mean of b).
int zeroMeanSad(const std::uint8_t* a, int stepA, const std::uint8_t* b, int stepB, int offset) {
  constexpr int h = StereoMatcher::kPatchHalf;
  int sum = 0;
  for (int dy = -h; dy <= h; ++dy) {
    const std::uint8_t* ra = a + dy * stepA;
    const std::uint8_t* rb = b + dy * stepB;
    for (int dx = -h; dx <= h; ++dx) sum += std::abs(kPatchArea * (ra[dx] - rb[dx]) - offset);
  }
  return sum;
}

}  // namespace

void StereoMatcher::match(const StereoView& left, const StereoView& right, const ScaleLevels& scales,
                          float bf, float minDepth, std::vector<float>& uRight, std::vector<float>& depth) {
  const std::size_t n = left.keypoints.size();
  uRight.assign(n, -1.f);
  depth.assign(n, -1.f);
  if (n == 0 || right.keypoints.empty() || left.pyramid.empty() || right.pyramid.empty()) return;
  indexRightRows(right, scales, left.pyramid[0].rows);

  // Each left keypoint's match depends on that keypoint alone, so the two halves can run on two
  // threads; the costs are then gathered in keypoint order, as one thread would.
  cost_.assign(n, -1);
  const float maxDisparity = bf / minDepth;
  auto matchRange = [&](std::size_t begin, std::size_t end) {
    for (std::size_t iL = begin; iL < end; ++iL) matchOne(left, right, bf, maxDisparity, iL, uRight, depth);
  };
  if (parallel_ && n >= kMinKeypointsForTwoThreads) {
    if (!helper_) helper_ = std::make_unique<HelperThread>();
    helper_->run([&] { matchRange(n / 2, n); });
    HelperThread::JoinGuard joinHelper(*helper_);
    matchRange(0, n / 2);
  } else {
    matchRange(0, n);
  }
  costAndIndex_.clear();
  for (std::size_t iL = 0; iL < n; ++iL)
    if (cost_[iL] >= 0) costAndIndex_.emplace_back(cost_[iL], static_cast<int>(iL));

  if (costAndIndex_.empty()) return;
  std::sort(costAndIndex_.begin(), costAndIndex_.end());
  const float median = static_cast<float>(costAndIndex_[costAndIndex_.size() / 2].first);
  const float threshold = kOutlierFactor * median;
  for (auto it = costAndIndex_.rbegin(); it != costAndIndex_.rend(); ++it) {
    if (static_cast<float>(it->first) <= threshold) break;
    uRight[static_cast<std::size_t>(it->second)] = -1.f;
    depth[static_cast<std::size_t>(it->second)] = -1.f;
  }
}

void StereoMatcher::indexRightRows(const StereoView& right, const ScaleLevels& scales, int rows) {
  // Right keypoints indexed by every image row their band covers (flat CSR layout).
  rows_ = rows;
  rowStart_.assign(static_cast<std::size_t>(rows) + 1, 0);
  auto bandOf = [&](const Keypoint& k) {
    const float r = kRowBand * scales.scale[static_cast<std::size_t>(k.octave)];
    return std::pair{std::max(0, static_cast<int>(std::floor(k.v - r))),
                     std::min(rows - 1, static_cast<int>(std::ceil(k.v + r)))};
  };
  for (const Keypoint& k : right.keypoints) {
    const auto [r0, r1] = bandOf(k);
    for (int y = r0; y <= r1; ++y) ++rowStart_[static_cast<std::size_t>(y) + 1];
  }
  for (int y = 0; y < rows; ++y) rowStart_[static_cast<std::size_t>(y) + 1] += rowStart_[static_cast<std::size_t>(y)];
  rowEntries_.resize(static_cast<std::size_t>(rowStart_.back()));
  rowFill_.assign(rowStart_.begin(), rowStart_.end() - 1);
  for (std::size_t i = 0; i < right.keypoints.size(); ++i) {
    const auto [r0, r1] = bandOf(right.keypoints[i]);
    for (int y = r0; y <= r1; ++y) rowEntries_[static_cast<std::size_t>(rowFill_[static_cast<std::size_t>(y)]++)] = static_cast<int>(i);
  }
}

int StereoMatcher::bestRightCandidate(const StereoView& left, const StereoView& right, std::size_t iL,
                                      float maxDisparity) const {
  const Keypoint& kl = left.keypoints[iL];
  const int level = kl.octave;
  const auto row = static_cast<std::size_t>(kl.v);
  const float minU = kl.u - maxDisparity, maxU = kl.u;
  int bestDistance = kMaxDescriptorDistance;
  int bestRight = -1;
  const OrbDescriptor& dl = left.descriptors[iL];
  for (int e = rowStart_[row]; e < rowStart_[row + 1]; ++e) {
    const int iR = rowEntries_[static_cast<std::size_t>(e)];
    const Keypoint& kr = right.keypoints[static_cast<std::size_t>(iR)];
    if (kr.octave < level - 1 || kr.octave > level + 1) continue;
    if (kr.u < minU || kr.u > maxU) continue;
    const int d = hammingDistance(dl, right.descriptors[static_cast<std::size_t>(iR)]);
    if (d < bestDistance) {
      bestDistance = d;
      bestRight = iR;
    }
  }
  return bestRight;
}

void StereoMatcher::matchOne(const StereoView& left, const StereoView& right, float bf, float maxDisparity,
                             std::size_t iL, std::vector<float>& uRight, std::vector<float>& depth) {
  const float minDisparity = 0.f;
  const Keypoint& kl = left.keypoints[iL];
  const int level = kl.octave;
  const int row = static_cast<int>(kl.v);
  if (row < 0 || row >= rows_) return;
  if (kl.u - minDisparity < 0.f) return;
  const int bestRight = bestRightCandidate(left, right, iL, maxDisparity);
  if (bestRight < 0) return;

  // Sub-pixel refinement by patch correlation on the left keypoint's level.
  const cv::Mat& imL = left.pyramid[static_cast<std::size_t>(level)];
  const cv::Mat& imR = right.pyramid[static_cast<std::size_t>(level)];
  // Level <-> level-0 coordinates (two divisions: nothing beside the 11-position SAD below).
  const PyramidLevelMap mapL = PyramidLevelMap::between(left.pyramid[0], imL);
  const PyramidLevelMap mapR = PyramidLevelMap::between(right.pyramid[0], imR);
  const int uL = cvRound(mapL.fromBaseX(kl.u)), vL = cvRound(mapL.fromBaseY(kl.v));
  const int uR0 = cvRound(mapR.fromBaseX(right.keypoints[static_cast<std::size_t>(bestRight)].u));
  if (uR0 - kSlide - kPatchHalf < 0 || uR0 + kSlide + kPatchHalf >= imR.cols) return;
  if (vL - kPatchHalf < 0 || vL + kPatchHalf >= imL.rows || uL - kPatchHalf < 0 || uL + kPatchHalf >= imL.cols) return;
  const std::uint8_t* patchL = imL.ptr<std::uint8_t>(vL) + uL;
  const std::uint8_t* rowR = imR.ptr<std::uint8_t>(vL);
  const int stepL = static_cast<int>(imL.step), stepR = static_cast<int>(imR.step);
  // Patch sums from column sums: the left patch's once, the right one's slid along the row.
  int sumL = 0;
  for (int dx = -kPatchHalf; dx <= kPatchHalf; ++dx) sumL += columnSum(patchL, stepL, dx);
  int columnsR[2 * (kSlide + kPatchHalf) + 1];
  for (int x = -kSlide - kPatchHalf; x <= kSlide + kPatchHalf; ++x)
    columnsR[x + kSlide + kPatchHalf] = columnSum(rowR + uR0, stepR, x);
  int sumR = 0;
  for (int x = 0; x < 2 * kPatchHalf + 1; ++x) sumR += columnsR[x];
  int costs[2 * kSlide + 1];
  int bestCost = INT_MAX, bestShift = 0;
  for (int s = -kSlide; s <= kSlide; ++s) {
    if (s > -kSlide) sumR += columnsR[s + kSlide + 2 * kPatchHalf] - columnsR[s + kSlide - 1];
    const int c = zeroMeanSad(patchL, stepL, rowR + uR0 + s, stepR, sumL - sumR);
    costs[s + kSlide] = c;
    if (c < bestCost) {
      bestCost = c;
      bestShift = s;
    }
  }
  if (bestShift == -kSlide || bestShift == kSlide) return;  // minimum not bracketed

  const float c1 = static_cast<float>(costs[kSlide + bestShift - 1]);
  const float c2 = static_cast<float>(costs[kSlide + bestShift]);
  const float c3 = static_cast<float>(costs[kSlide + bestShift + 1]);
  const float curvature = 2.f * (c1 + c3 - 2.f * c2);
  if (curvature <= 0.f) return;  // flat: no reliable minimum
  const float delta = (c1 - c3) / curvature;
  if (delta < -1.f || delta > 1.f) return;

  float uR = mapR.toBaseX(static_cast<float>(uR0 + bestShift) + delta);
  float disparity = kl.u - uR;
  if (disparity < minDisparity || disparity >= maxDisparity) return;
  if (disparity <= 0.f) {
    // A point at infinity: keep it as (nearly) zero disparity rather than lose it.
    disparity = 0.01f;
    uR = kl.u - disparity;
  }
  uRight[iL] = uR;
  depth[iL] = bf / disparity;
  cost_[iL] = bestCost;
}

}  // namespace orbis
