// orbis/features/fast_corners.hpp — FAST-9 corners as a score map: the corners, scores and order
// of OpenCV's cv::FAST(image, keypoints, threshold, nonmaxSuppression = true), computed for a
// whole area in one pass so that several thresholds and sub-areas can be read from it.
//
// Contract: fastScoreMap() writes, for every pixel of `area` (which must keep 3 pixels from the
// image's edges), OpenCV's cornerScore<16> where the pixel is a FAST-9 corner at `threshold`
// (brighter, or darker, than the centre by more than the threshold on 9 contiguous pixels of the
// radius-3 circle) and 0 elsewhere; scores of corners are at least the threshold and below 255.
// fastCornersOfScoreMap() appends, in row-major order, the pixels of a sub-area of such a map
// whose score is at least `threshold` (not below the map's) and larger than each of their eight
// neighbours inside the sub-area (outside counts as 0) — exactly what cv::FAST reports for the
// image cropped to that sub-area plus 3 pixels — keeping those left of `keepBelowX` (map
// columns). The code is picked once at run time: AVX-512BW scores (with AVX2 suppression) or AVX2
// where the CPU has them, else portable one-pixel-at-a-time code (correct, but slower than
// cv::FAST: OrbExtractor uses cv::FAST there). Every path gives the same output. Thread-safe;
// the buffers are the caller's.
// Design and measurements: docs/notes/2026-11-27-own-fast.md.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace orbis {

// A corner of a score map: position in map coordinates and its score.
struct FastCorner {
  int x;      // column in the score map
  int y;      // row in the score map
  int score;  // OpenCV's cornerScore<16>
};

// Buffers fastCornersOfScoreMap() reuses between calls.
struct FastScratch {
  std::vector<std::uint8_t> padded;  // the sub-area's scores with a zero border
  std::vector<std::uint32_t> words;  // one row's kept pixels, a bit each
};

// Which code computes the map and its corners: the best this CPU runs, or one forced (tests).
enum class FastCode { Best, Portable, Avx2, Avx512 };

// Whether this build and CPU can run `code`; FastCode::Best is always available.
bool fastCodeAvailable(FastCode code);

// Whether FastCode::Best is vector code (faster than cv::FAST), not the portable fallback.
bool fastScoreMapIsVectorised();

// Scores of `area` of an 8-bit one-channel image into `scores` (CV_8U, area.height x
// area.width; an existing header of that size and type, such as a ROI, is written in place).
void fastScoreMap(const cv::Mat& image, const cv::Rect& area, int threshold, cv::Mat& scores,
                  FastCode code = FastCode::Best);

// Corners of `area` of a score map (see the contract above), appended to `corners`.
void fastCornersOfScoreMap(const cv::Mat& scores, const cv::Rect& area, int threshold, int keepBelowX,
                           FastScratch& scratch, std::vector<FastCorner>& corners, FastCode code = FastCode::Best);

}  // namespace orbis
