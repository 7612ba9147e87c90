// orbis/features/orb_extractor.hpp — ORB-SLAM's ORB extractor: well-spread FAST corners with
// intensity-centroid orientation and rotated BRIEF descriptors.
//
// Contract: satisfies FeatureExtractor. Per frame: a scale pyramid (OrbParams levels x
// scaleFactor); a budget per level that falls geometrically with the level; FAST corners at
// iniThFast over each level, then FAST at minThFast again in every ~30 px cell left empty; a
// quadtree over each level's corners that keeps the strongest corner per node (of equal
// scores, the one nearest the node's centre), so the keypoints cover the whole image;
// orientation by intensity centroid over a circle of radius 15; 256-bit rotated BRIEF with the
// standard learned pattern on the level blurred by a 7x7 Gaussian (sigma 2). Keypoints are
// ordered by level. The total may exceed the budget by a few (the quadtree splits four ways)
// and falls short on images with too few corners.
// Deterministic; not thread-safe (one extractor per image stream: buffers are reused). With
// setParallelLevels(true) the levels are shared between the caller's thread and a helper kept by
// the extractor: either thread converts bands of level 0, the one that completes it builds the
// rest of the pyramid while the other starts on level 0, and the levels go to whichever is free
// (each level's corners, quadtree and descriptors depend on that level alone, so the output is
// bit-identical to the serial one); for an extractor that runs alone on a frame (monocular,
// RGB-D). A stereo pair goes through extractPair, the same scheme over both images (the bands
// of both, then their levels, largest first), so that a thread the scheduler holds back (mapping
// shares the cores) delays a band or a level, not a whole image; the output is bit-identical to
// extract() on each image.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/extractor.hpp"
#include "orbis/features/fast_corners.hpp"
#include "orbis/features/image_pyramid.hpp"
#include "orbis/features/keypoint.hpp"
#include "orbis/features/orb_params.hpp"
#include "orbis/util/helper_thread.hpp"

namespace orbis {

// ORB-SLAM's extractor: FAST on every level with a fallback threshold per cell, a quadtree keeping
// the strongest corner per node, intensity-centroid orientation, rotated BRIEF.
class OrbExtractor : public PyramidExtractorBase {
 public:
  // @{
  // The descriptor's patch and half of it.
  static constexpr int kPatchSize = 31;
  static constexpr int kHalfPatch = 15;
  // @}
  static constexpr int kEdge = 19;        // keypoints keep this far from each level's edge (ORB-SLAM)
  static constexpr int kCellSize = 30;    // FAST fallback cells, level pixels
  // Gaussian applied before the binary tests (ORB-SLAM: 7x7, sigma 2), as the 8-bit fixed-point
  // taps (sum 256) that cv::GaussianBlur quantises it to on a whole image, as in ORB-SLAM2.
  static constexpr int kBlurSize = 7;
  // @{
  // The blur's σ and its fixed-point taps.
  static constexpr double kBlurSigma = 2.0;
  static constexpr std::array<int, kBlurSize> kBlurTapsQ8 = {18, 34, 48, 56, 48, 34, 18};
  // @}

  // An extractor with the given budget, levels and thresholds.
  explicit OrbExtractor(const OrbParams& params = {});

  // One row of the orientation circle as a byte mask over u = -16..15.
  struct CircleRowMask {
    // The mask bytes.
    alignas(16) std::uint8_t bytes[32];
  };

  // Keypoints and descriptors of an 8-bit grey or BGR image.
  void extract(const cv::Mat& image, std::vector<Keypoint>& keypoints,
               std::vector<OrbDescriptor>& descriptors);

  // extract() of two images by two extractors (a stereo pair), on the caller's thread and
  // first's helper thread; each output is bit-identical to that extractor's extract().
  static void extractPair(OrbExtractor& first, const cv::Mat& firstImage, std::vector<Keypoint>& firstKeypoints,
                          std::vector<OrbDescriptor>& firstDescriptors, OrbExtractor& second,
                          const cv::Mat& secondImage, std::vector<Keypoint>& secondKeypoints,
                          std::vector<OrbDescriptor>& secondDescriptors);

  // Keypoints wanted on each level (sums to params().features).
  std::span<const int> featuresPerLevel() const { return featuresPerLevel_; }
  // Extract one image's pyramid levels on two threads (the same keypoints and descriptors either way).
  void setParallelLevels(bool on) { parallelLevels_ = on; }
  /** FAST by cv::FAST (true) or by one score map per level (fast_corners.hpp; false, the default
   *  where the CPU runs its vector code). Both give the same corners; for comparisons. */
  void setOpenCvFast(bool on) { openCvFast_ = on; }
  /** Whether cv::FAST finds the corners (see setOpenCvFast()). */ bool openCvFast() const { return openCvFast_; }
  /** Whether setParallelLevels(true) is in force. */ bool parallelLevels() const { return parallelLevels_; }

 private:
  struct Corner {
    float x, y, response;
  };
  struct Node {
    float x0, y0, x1, y1;
    int begin, end;  // range in corners_
  };

  // The buffers one level's detection and selection reuse; one per thread working on levels.
  struct LevelScratch {
    std::vector<cv::KeyPoint> fast;
    cv::Mat fastScores;  // the level's FAST score map (fast_corners.hpp), where vectorised
    FastScratch fastScratch;
    std::vector<FastCorner> fastCorners;
    std::vector<Corner> corners, sorted;
    std::vector<std::uint8_t> quadrant;
    std::vector<Node> nodes, nextNodes;
    std::vector<int> cellCount, selected, splittable;
  };

  // The levels of one or two images (one extractor each) on the caller's thread and
  // helperOwner's helper thread.
  static void extractOnTwoThreads(std::span<OrbExtractor* const> extractors, std::span<const cv::Mat* const> images,
                                  OrbExtractor& helperOwner);
  void startLevels(const cv::Mat& image, std::vector<Keypoint>& keypoints, std::vector<OrbDescriptor>& descriptors);
  void collectLevels(std::vector<Keypoint>& keypoints, std::vector<OrbDescriptor>& descriptors) const;
  void extractLevel(int l, LevelScratch& s);
  void detectCorners(const cv::Mat& level, LevelScratch& s) const;
  static void distribute(LevelScratch& s, int wanted, float minX, float minY, float maxX, float maxY);
  static void splitNode(LevelScratch& s, const Node& n, Node children[4], int& count);

  std::vector<int> featuresPerLevel_;
  std::array<CircleRowMask, kHalfPatch + 1> circleRows_{};  // orientation circle, per row offset
  std::vector<cv::Mat> blurred_;  // per level: sizes differ, so one buffer would reallocate
  std::array<LevelScratch, 2> scratch_;
  std::vector<std::vector<Keypoint>> levelKeypoints_;        // per level, before concatenation
  std::vector<std::vector<OrbDescriptor>> levelDescriptors_;
  bool parallelLevels_ = false;
  bool openCvFast_ = !fastScoreMapIsVectorised();
  std::unique_ptr<HelperThread> helper_;  // the second thread of setParallelLevels(true), kept between frames
};

static_assert(FeatureExtractor<OrbExtractor>);

// Which code computes orbBlur: the best this CPU runs, or one forced (tests). Every code gives
// the same bits; the vector codes need a view with 3 pixels of context and at least 16 (AVX2) or
// 32 (AVX-512BW) columns, and leave other images to the portable code (OpenCV's sepFilter2D).
enum class BlurCode { Best, Portable, Avx2, Avx512 };

// Whether this build and CPU can run `code`; Best and Portable always can.
bool blurCodeAvailable(BlurCode code);

// The extractor's pre-descriptor blur: `dst` = `src` filtered by OrbExtractor::kBlurTapsQ8 in
// both directions, reflecting (101) at the borders of src's parent image. Equal to
// cv::GaussianBlur(7x7, sigma 2) of a whole image up to rounding ties (off by one). `code` must
// be available.
void orbBlur(const cv::Mat& src, cv::Mat& dst, BlurCode code = BlurCode::Best);

}  // namespace orbis
