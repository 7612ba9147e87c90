// ORB-SLAM's extractor; see include/orbis/features/orb_extractor.hpp for the contract.
#include "orbis/features/orb_extractor.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <memory>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__SSE2__) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define ORBIS_AVX2_DISPATCH 1
#endif

#include "../util/cpu_dispatch.hpp"
#include "orb_pattern.hpp"

namespace orbis {
namespace {

// Intensity centroid of the circular patch (radius kHalfPatch) around `center`; the angle of
// the vector from the centre to the centroid, in degrees. Integer moments: exact and fast.
#if defined(__SSE2__)
// Each row is read as 32 bytes (u = -16..15) and masked to the circle: the row sum by
// _mm_sad_epu8 feeds m01, the sum of u * intensity by _mm_madd_epi16 feeds m10. The same
// integer moments as the scalar form, 3.4x faster (72 against 246 ns per keypoint, EuRoC).
float centroidAngle(const std::uint8_t* center, int step, const OrbExtractor::CircleRowMask* masks) {
  constexpr int r = OrbExtractor::kHalfPatch;
  const __m128i zero = _mm_setzero_si128();
  const __m128i w0 = _mm_setr_epi16(-16, -15, -14, -13, -12, -11, -10, -9);
  const __m128i w1 = _mm_setr_epi16(-8, -7, -6, -5, -4, -3, -2, -1);
  const __m128i w2 = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
  const __m128i w3 = _mm_setr_epi16(8, 9, 10, 11, 12, 13, 14, 15);
  __m128i m10 = zero;
  int m01 = 0;
  for (int v = -r; v <= r; ++v) {
    const std::uint8_t* row = center + v * step - 16;
    const OrbExtractor::CircleRowMask& mask = masks[v < 0 ? -v : v];
    const __m128i lo = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row)),
                                     _mm_load_si128(reinterpret_cast<const __m128i*>(mask.bytes)));
    const __m128i hi = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 16)),
                                     _mm_load_si128(reinterpret_cast<const __m128i*>(mask.bytes + 16)));
    const __m128i sums = _mm_add_epi64(_mm_sad_epu8(lo, zero), _mm_sad_epu8(hi, zero));
    m01 += v * (_mm_cvtsi128_si32(sums) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(sums, sums)));
    m10 = _mm_add_epi32(m10, _mm_add_epi32(_mm_madd_epi16(_mm_unpacklo_epi8(lo, zero), w0),
                                           _mm_madd_epi16(_mm_unpackhi_epi8(lo, zero), w1)));
    m10 = _mm_add_epi32(m10, _mm_add_epi32(_mm_madd_epi16(_mm_unpacklo_epi8(hi, zero), w2),
                                           _mm_madd_epi16(_mm_unpackhi_epi8(hi, zero), w3)));
  }
  m10 = _mm_add_epi32(m10, _mm_shuffle_epi32(m10, _MM_SHUFFLE(1, 0, 3, 2)));
  m10 = _mm_add_epi32(m10, _mm_shuffle_epi32(m10, _MM_SHUFFLE(2, 3, 0, 1)));
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(_mm_cvtsi128_si32(m10)));
}
#else
float centroidAngle(const std::uint8_t* center, int step, const OrbExtractor::CircleRowMask* masks) {
  constexpr int r = OrbExtractor::kHalfPatch;
  int m01 = 0, m10 = 0;
  for (int v = -r; v <= r; ++v) {
    const std::uint8_t* row = center + v * step;
    const std::uint8_t* mask = masks[v < 0 ? -v : v].bytes + 16;
    int sum = 0;
    for (int u = -16; u < 16; ++u) {
      const int value = mask[u] ? row[u] : 0;
      sum += value;
      m10 += u * value;
    }
    m01 += v * sum;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}
#endif

// The pattern as floats, one array per coordinate, points 2i and 2i+1 forming test i.
struct PatternSoA {
  alignas(32) float x[2 * OrbDescriptor::kBits];  // 32: the AVX2 path loads 8 at a time
  alignas(32) float y[2 * OrbDescriptor::kBits];
  PatternSoA() {
    for (int k = 0; k < 2 * OrbDescriptor::kBits; ++k) {
      x[k] = static_cast<float>(detail::kOrbPattern[2 * k]);
      y[k] = static_cast<float>(detail::kOrbPattern[2 * k + 1]);
    }
  }
};
const PatternSoA& pattern() {
  static const PatternSoA p;
  return p;
}

// Each pattern point rotated by (cos, sin) = (a, b), rounded to the nearest pixel
// (round-half-even, like cvRound), as an offset from the centre in a buffer of row `step`.
void rotatedOffsets(float a, float b, int step, int* offset) {
  constexpr int kPoints = 2 * OrbDescriptor::kBits;
  const PatternSoA& p = pattern();
#if defined(__SSE2__)
  const __m128 va = _mm_set1_ps(a), vb = _mm_set1_ps(b);
  const __m128 vstep = _mm_set1_ps(static_cast<float>(step));
  for (int k = 0; k < kPoints; k += 4) {
    const __m128 x = _mm_load_ps(p.x + k), y = _mm_load_ps(p.y + k);
    const __m128i ix = _mm_cvtps_epi32(_mm_sub_ps(_mm_mul_ps(x, va), _mm_mul_ps(y, vb)));
    const __m128i iy = _mm_cvtps_epi32(_mm_add_ps(_mm_mul_ps(x, vb), _mm_mul_ps(y, va)));
    // iy*step + ix is exact in float (|value| < 2^24), so no 32-bit integer multiply needed.
    const __m128 o = _mm_add_ps(_mm_mul_ps(_mm_cvtepi32_ps(iy), vstep), _mm_cvtepi32_ps(ix));
    _mm_store_si128(reinterpret_cast<__m128i*>(offset + k), _mm_cvtps_epi32(o));
  }
#else
  for (int k = 0; k < kPoints; ++k)
    offset[k] = cvRound(p.x[k] * b + p.y[k] * a) * step + cvRound(p.x[k] * a - p.y[k] * b);
#endif
}

#if defined(ORBIS_AVX2_DISPATCH)
// The same with 8 lanes: the rotation was half of a descriptor's time with 4 (177 of ~360 ns;
// 75 ns here). Chosen at run time, as default builds target baseline x86-64. The target is
// "avx2" without "fma", so the products are not fused and round exactly as above.
__attribute__((target("avx2"))) void rotatedOffsetsAvx2(float a, float b, int step, int* offset) {
  constexpr int kPoints = 2 * OrbDescriptor::kBits;
  const PatternSoA& p = pattern();
  const __m256 va = _mm256_set1_ps(a), vb = _mm256_set1_ps(b);
  const __m256i vstep = _mm256_set1_epi32(step);
  for (int k = 0; k < kPoints; k += 8) {
    const __m256 x = _mm256_load_ps(p.x + k), y = _mm256_load_ps(p.y + k);
    const __m256i ix = _mm256_cvtps_epi32(_mm256_sub_ps(_mm256_mul_ps(x, va), _mm256_mul_ps(y, vb)));
    const __m256i iy = _mm256_cvtps_epi32(_mm256_add_ps(_mm256_mul_ps(x, vb), _mm256_mul_ps(y, va)));
    _mm256_store_si256(reinterpret_cast<__m256i*>(offset + k), _mm256_add_epi32(_mm256_mullo_epi32(iy, vstep), ix));
  }
}
#endif

// Rotated BRIEF: the pattern rotated by the keypoint angle, then 256 intensity comparisons.
void briefDescriptor(const std::uint8_t* center, int step, float angleDeg, OrbDescriptor& out) {
  const float rad = angleDeg * static_cast<float>(CV_PI / 180.0);
  const float a = std::cos(rad), b = std::sin(rad);
  alignas(32) int offset[2 * OrbDescriptor::kBits];
#if defined(ORBIS_AVX2_DISPATCH)
  if (detail::cpuHasAvx2())
    rotatedOffsetsAvx2(a, b, step, offset);
  else
#endif
    rotatedOffsets(a, b, step, offset);
  std::uint8_t* bytes = out.bytes();
  const int* o = offset;
  for (int i = 0; i < OrbDescriptor::kBytes; ++i) {
    int byte = 0;
    for (int bit = 0; bit < 8; ++bit, o += 2) byte |= (center[o[0]] < center[o[1]]) << bit;
    bytes[i] = static_cast<std::uint8_t>(byte);
  }
}

}  // namespace

OrbExtractor::OrbExtractor(const OrbParams& params)
    : PyramidExtractorBase(params) {
  // Budget per level proportional to the level's area ratio along a geometric series, the
  // last level taking the remainder (as ORB-SLAM).
  const int n = scales_.levels();
  featuresPerLevel_.assign(static_cast<std::size_t>(n), 0);
  const float factor = 1.f / params.scaleFactor;
  float perLevel = static_cast<float>(params.features) * (1.f - factor) /
                   (1.f - std::pow(factor, static_cast<float>(n)));
  if (n == 1) perLevel = static_cast<float>(params.features);
  int assigned = 0;
  for (int l = 0; l < n - 1; ++l) {
    featuresPerLevel_[static_cast<std::size_t>(l)] = static_cast<int>(std::lround(perLevel));
    assigned += featuresPerLevel_[static_cast<std::size_t>(l)];
    perLevel *= factor;
  }
  featuresPerLevel_[static_cast<std::size_t>(n - 1)] = std::max(params.features - assigned, 0);
  blurred_.resize(static_cast<std::size_t>(n));

  // Half-width of each row of the orientation circle, made symmetric under swapping u and v so
  // the moments do not favour an axis.
  const int r = kHalfPatch;
  std::vector<int> halfWidth(static_cast<std::size_t>(r + 1), 0);
  const int vmax = cvFloor(r * std::sqrt(2.f) / 2 + 1);
  const int vmin = cvCeil(r * std::sqrt(2.f) / 2);
  for (int v = 0; v <= vmax; ++v)
    halfWidth[static_cast<std::size_t>(v)] = cvRound(std::sqrt(double(r * r - v * v)));
  for (int v = r, v0 = 0; v >= vmin; --v) {
    while (halfWidth[static_cast<std::size_t>(v0)] == halfWidth[static_cast<std::size_t>(v0 + 1)]) ++v0;
    halfWidth[static_cast<std::size_t>(v)] = v0;
    ++v0;
  }
  for (int v = 0; v <= r; ++v) {
    const int d = halfWidth[static_cast<std::size_t>(v)];
    for (int u = -16; u < 16; ++u)
      circleRows_[static_cast<std::size_t>(v)].bytes[u + 16] = (u >= -d && u <= d) ? 0xFF : 0;
  }
}

void OrbExtractor::detectCorners(const cv::Mat& level, LevelScratch& s) const {
  std::vector<Corner>& corners = s.corners;
  corners.clear();
  const int minX = kEdge, minY = kEdge, maxX = level.cols - kEdge, maxY = level.rows - kEdge;
  if (maxX - minX < kCellSize / 2 || maxY - minY < kCellSize / 2) return;

  // FAST needs 3 pixels of context beyond the area where it reports corners. OpenCV's FAST
  // runs 16 pixels at a time and finishes each row one pixel at a time: a 30 px wide area
  // costs 2.6x a 33 px one per pixel (EuRoC, measured). So the searched width is widened to
  // 16k + 1 (into the level's edge margin, which is wider than 16 px, or the neighbouring
  // cells) and the corners outside the area dropped; only the suppression of corners in the
  // area's last column can see the extra columns. Where our vectorised FAST runs, the scores of
  // the whole level are computed once at the lower threshold and each area's corners read from
  // them, the same corners as cv::FAST's over the same widened areas
  // (docs/notes/2026-11-27-own-fast.md).
  const bool scoreMap = !openCvFast_;
  if (scoreMap)
    fastScoreMap(level, cv::Rect(minX, minY, level.cols - 3 - minX, maxY - minY),
                 std::min(params_.iniThFast, params_.minThFast), s.fastScores);
  auto fastIn = [&](int x0, int y0, int x1, int y1, int threshold) {
    const int padded = std::min(((x1 - x0 + 14) / 16) * 16 + 1, level.cols - 3 - x0);  // >= x1 - x0: x1 <= cols - kEdge
    if (scoreMap) {
      s.fastCorners.clear();
      fastCornersOfScoreMap(s.fastScores, cv::Rect(x0 - minX, y0 - minY, padded, y1 - y0), threshold, x1 - minX,
                            s.fastScratch, s.fastCorners);
      for (const FastCorner& c : s.fastCorners)
        corners.push_back({static_cast<float>(c.x + minX), static_cast<float>(c.y + minY), static_cast<float>(c.score)});
      return;
    }
    cv::FAST(level(cv::Rect(x0 - 3, y0 - 3, padded + 6, y1 - y0 + 6)), s.fast, threshold, true);
    const auto right = static_cast<float>(x1 - x0 + 3);
    for (const cv::KeyPoint& k : s.fast)
      if (k.pt.x < right)
        corners.push_back({k.pt.x + static_cast<float>(x0 - 3), k.pt.y + static_cast<float>(y0 - 3), k.response});
  };

  // One pass over the whole level at the high threshold finds the same corners as per-cell
  // passes would, without their overlap and per-call overhead.
  fastIn(minX, minY, maxX, maxY, params_.iniThFast);

  const int cols = std::max(1, (maxX - minX) / kCellSize);
  const int rows = std::max(1, (maxY - minY) / kCellSize);
  const int cellW = (maxX - minX + cols - 1) / cols;
  const int cellH = (maxY - minY + rows - 1) / rows;
  std::vector<int>& cellCount = s.cellCount;
  cellCount.assign(static_cast<std::size_t>(cols * rows), 0);
  for (const Corner& c : corners) {
    const int cx = std::min(cols - 1, (static_cast<int>(c.x) - minX) / cellW);
    const int cy = std::min(rows - 1, (static_cast<int>(c.y) - minY) / cellH);
    ++cellCount[static_cast<std::size_t>(cy * cols + cx)];
  }
  // Cells the high threshold left empty (low contrast) get a second chance at the low one.
  // Empty cells are searched in rectangles (a run along the row, extended down while the
  // cells below are empty too): the same corners inside each cell, without re-reading the
  // 3-pixel context of every cell or paying the per-call overhead per cell.
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols;) {
      int* counts = cellCount.data() + static_cast<std::ptrdiff_t>(cy * cols);
      if (counts[cx] != 0) {
        ++cx;
        continue;
      }
      int runEnd = cx + 1;
      while (runEnd < cols && counts[runEnd] == 0) ++runEnd;
      int rowEnd = cy + 1;
      for (; rowEnd < rows; ++rowEnd) {
        int* below = cellCount.data() + static_cast<std::ptrdiff_t>(rowEnd * cols);
        if (std::any_of(below + cx, below + runEnd, [](int n) { return n != 0; })) break;
        std::fill(below + cx, below + runEnd, -1);  // searched with this rectangle
      }
      const int x0 = minX + cx * cellW, x1 = std::min(maxX, minX + runEnd * cellW);
      const int y0 = minY + cy * cellH, y1 = std::min(maxY, minY + rowEnd * cellH);
      if (x1 > x0 && y1 > y0) fastIn(x0, y0, x1, y1, params_.minThFast);
      cx = runEnd;
    }
  }
}

void OrbExtractor::splitNode(LevelScratch& s, const Node& n, Node children[4], int& count) {
  const float halfX = std::ceil((n.x1 - n.x0) / 2.f), halfY = std::ceil((n.y1 - n.y0) / 2.f);
  const float midX = n.x0 + halfX, midY = n.y0 + halfY;
  // A four-way split by counting and scattering, without data-dependent branches: three
  // std::partition calls, branching on unpredictable positions, took twice the time (perf share
  // 3.8% against 1.9% of EuRoC extraction). The order within a node does not matter:
  // distribute() resolves equal scores by position.
  Corner* first = s.corners.data() + n.begin;
  const auto size = static_cast<std::size_t>(n.end - n.begin);
  s.quadrant.resize(size);
  int counts[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < size; ++i) {
    const int q = static_cast<int>(first[i].x >= midX) + 2 * static_cast<int>(first[i].y >= midY);
    s.quadrant[i] = static_cast<std::uint8_t>(q);
    ++counts[q];
  }
  int offsets[4] = {0, counts[0], counts[0] + counts[1], counts[0] + counts[1] + counts[2]};
  const int begins[4] = {offsets[0], offsets[1], offsets[2], offsets[3]};
  s.sorted.resize(size);
  for (std::size_t i = 0; i < size; ++i) s.sorted[static_cast<std::size_t>(offsets[s.quadrant[i]]++)] = first[i];
  std::copy(s.sorted.begin(), s.sorted.end(), first);
  const Node quarters[4] = {{n.x0, n.y0, midX, midY, n.begin + begins[0], n.begin + begins[1]},
                            {midX, n.y0, n.x1, midY, n.begin + begins[1], n.begin + begins[2]},
                            {n.x0, midY, midX, n.y1, n.begin + begins[2], n.begin + begins[3]},
                            {midX, midY, n.x1, n.y1, n.begin + begins[3], n.end}};
  count = 0;
  for (const Node& q : quarters)
    if (q.end > q.begin) children[count++] = q;
}

void OrbExtractor::distribute(LevelScratch& s, int wanted, float minX, float minY, float maxX, float maxY) {
  std::vector<Corner>& corners = s.corners;
  std::vector<Node>& nodes = s.nodes;
  std::vector<Node>& nextNodes = s.nextNodes;
  std::vector<int>& splittable = s.splittable;
  s.selected.clear();
  if (corners.empty() || wanted <= 0) return;
  const auto target = static_cast<std::size_t>(wanted);

  // Root nodes: square-ish vertical strips so the quadtree cells stay roughly square.
  const int strips = std::max(1, static_cast<int>(std::lround((maxX - minX) / (maxY - minY))));
  const float stripW = (maxX - minX) / static_cast<float>(strips);
  nodes.clear();
  auto* begin = corners.data();
  for (int i = 0; i < strips; ++i) {
    const float x1 = i + 1 == strips ? maxX + 1.f : minX + stripW * static_cast<float>(i + 1);
    auto* end = std::partition(begin, corners.data() + corners.size(),
                               [x1](const Corner& c) { return c.x < x1; });
    if (end > begin)
      nodes.push_back({minX + stripW * static_cast<float>(i), minY, x1, maxY,
                        static_cast<int>(begin - corners.data()), static_cast<int>(end - corners.data())});
    begin = end;
  }

  Node children[4];
  int count = 0;
  for (;;) {
    nextNodes.clear();
    std::size_t expandable = 0;
    for (const Node& n : nodes) {
      if (n.end - n.begin == 1) {
        nextNodes.push_back(n);
        continue;
      }
      splitNode(s, n, children, count);
      for (int k = 0; k < count; ++k) {
        nextNodes.push_back(children[k]);
        if (children[k].end - children[k].begin > 1) ++expandable;
      }
    }
    const bool unchanged = nextNodes.size() == nodes.size();
    nodes.swap(nextNodes);
    if (nodes.size() >= target || unchanged) break;
    if (nodes.size() + 3 * expandable > target) {
      // A full round would overshoot: split the most populated nodes first, one at a time.
      while (nodes.size() < target) {
        splittable.clear();
        for (std::size_t i = 0; i < nodes.size(); ++i)
          if (nodes[i].end - nodes[i].begin > 1) splittable.push_back(static_cast<int>(i));
        if (splittable.empty()) break;
        std::stable_sort(splittable.begin(), splittable.end(), [&nodes](int a, int b) {
          const auto& na = nodes[static_cast<std::size_t>(a)];
          const auto& nb = nodes[static_cast<std::size_t>(b)];
          return na.end - na.begin > nb.end - nb.begin;
        });
        const std::size_t before = nodes.size();
        for (int idx : splittable) {
          splitNode(s, nodes[static_cast<std::size_t>(idx)], children, count);
          nodes[static_cast<std::size_t>(idx)] = children[0];
          for (int k = 1; k < count; ++k) nodes.push_back(children[k]);
          if (nodes.size() >= target) break;
        }
        if (nodes.size() == before) break;  // coincident corners cannot be separated
      }
      break;
    }
  }

  // The strongest corner of each node. FAST scores are small integers, so ties are common; the
  // corner nearest the node's centre wins them, which keeps the spread even (the first in
  // detection order would favour each node's top rows).
  for (const Node& n : nodes) {
    const float cx = 0.5f * (n.x0 + n.x1), cy = 0.5f * (n.y0 + n.y1);
    const auto offCentre = [&](const Corner& c) { return (c.x - cx) * (c.x - cx) + (c.y - cy) * (c.y - cy); };
    int best = n.begin;
    float bestResponse = corners[static_cast<std::size_t>(best)].response;
    float bestOffCentre = offCentre(corners[static_cast<std::size_t>(best)]);
    for (int i = n.begin + 1; i < n.end; ++i) {
      const Corner& c = corners[static_cast<std::size_t>(i)];
      if (c.response < bestResponse) continue;
      const float off = offCentre(c);
      if (c.response > bestResponse || off < bestOffCentre) {
        best = i;
        bestResponse = c.response;
        bestOffCentre = off;
      }
    }
    s.selected.push_back(best);
  }
}

void OrbExtractor::startLevels(const cv::Mat& image, std::vector<Keypoint>& keypoints,
                               std::vector<OrbDescriptor>& descriptors) {
  detail::checkGrayOrColour8u(image, "OrbExtractor input");
  keypoints.clear();
  descriptors.clear();
  levelKeypoints_.resize(static_cast<std::size_t>(levels()));
  levelDescriptors_.resize(static_cast<std::size_t>(levels()));
}

void OrbExtractor::collectLevels(std::vector<Keypoint>& keypoints, std::vector<OrbDescriptor>& descriptors) const {
  std::size_t total = 0;
  for (const auto& k : levelKeypoints_) total += k.size();
  keypoints.reserve(total);
  descriptors.reserve(total);
  for (int l = 0; l < levels(); ++l) {
    const auto level = static_cast<std::size_t>(l);
    keypoints.insert(keypoints.end(), levelKeypoints_[level].begin(), levelKeypoints_[level].end());
    descriptors.insert(descriptors.end(), levelDescriptors_[level].begin(), levelDescriptors_[level].end());
  }
}

void OrbExtractor::extract(const cv::Mat& image, std::vector<Keypoint>& keypoints,
                           std::vector<OrbDescriptor>& descriptors) {
  const int n = levels();
  startLevels(image, keypoints, descriptors);
  if (image.empty()) return;
  if (parallelLevels_ && n > 1) {
    OrbExtractor* const self[] = {this};
    const cv::Mat* const imageOf[] = {&image};
    extractOnTwoThreads(self, imageOf, *this);
  } else {
    pyramid_.build(image, scales_);  // a colour image is converted straight into level 0
    for (int l = 0; l < n; ++l) extractLevel(l, scratch_[0]);
  }
  collectLevels(keypoints, descriptors);
}

void OrbExtractor::extractPair(OrbExtractor& first, const cv::Mat& firstImage, std::vector<Keypoint>& firstKeypoints,
                               std::vector<OrbDescriptor>& firstDescriptors, OrbExtractor& second,
                               const cv::Mat& secondImage, std::vector<Keypoint>& secondKeypoints,
                               std::vector<OrbDescriptor>& secondDescriptors) {
  if (&first == &second || firstImage.empty() || secondImage.empty()) {  // nothing to share
    first.extract(firstImage, firstKeypoints, firstDescriptors);
    second.extract(secondImage, secondKeypoints, secondDescriptors);
    return;
  }
  first.startLevels(firstImage, firstKeypoints, firstDescriptors);
  second.startLevels(secondImage, secondKeypoints, secondDescriptors);
  OrbExtractor* const extractors[] = {&first, &second};
  const cv::Mat* const images[] = {&firstImage, &secondImage};
  extractOnTwoThreads(extractors, images, first);
  first.collectLevels(firstKeypoints, firstDescriptors);
  second.collectLevels(secondKeypoints, secondDescriptors);
}

void OrbExtractor::extractOnTwoThreads(std::span<OrbExtractor* const> extractors, std::span<const cv::Mat* const> images,
                                       OrbExtractor& helperOwner) {
  // Each image's level 0 is converted (or copied) in row bands that either thread claims; the
  // thread that completes an image's last band finishes its level 0 and builds the rest of its
  // pyramid (each level from the one before) while the other goes on; then the levels, largest
  // first (level l of every image before level l + 1), go to whichever thread is free. No step
  // waits for a particular thread, so a thread the scheduler holds back (threaded SLAM's mapping
  // shares the cores) delays only the band or level it holds; when the helper starts late, the
  // caller does everything itself. Which thread does a band or a level changes nothing in the
  // output. Why: docs/notes/2026-11-27-speed-paced-and-pairs.md.
  constexpr int kBands = 8;
  constexpr std::size_t kMaxImages = 2;
  const std::size_t m = extractors.size();
  CV_Assert(m == images.size() && m >= 1 && m <= kMaxImages);
  std::array<int, kMaxImages> n{};
  int maxLevels = 0;
  for (std::size_t i = 0; i < m; ++i) {
    n[i] = extractors[i]->levels();
    maxLevels = std::max(maxLevels, n[i]);
    extractors[i]->pyramid_.allocate(images[i]->size(), extractors[i]->scales_);
  }
  std::vector<std::pair<std::size_t, int>> tasks;  // (image, level)
  for (int l = 0; l < maxLevels; ++l)
    for (std::size_t i = 0; i < m; ++i)
      if (l < n[i]) tasks.emplace_back(i, l);
  std::array<std::atomic<int>, kMaxImages> bandsDone{};
  // Per image: levels 0 .. built - 1 are ready to read; n + 1: stop, nothing more comes.
  std::array<std::atomic<int>, kMaxImages> built{};
  std::atomic<int> bandsClaimed{0}, next{0};
  auto publish = [&](std::size_t i, int value) {
    built[i].store(value, std::memory_order_release);
    built[i].notify_all();
  };
  auto stopAll = [&] {
    for (std::size_t i = 0; i < m; ++i) publish(i, n[i] + 1);
  };
  auto convertAndBuild = [&] {
    const int bands = static_cast<int>(m) * kBands;
    for (int t = bandsClaimed++; t < bands; t = bandsClaimed++) {
      const auto i = static_cast<std::size_t>(t / kBands);
      const int b = t % kBands, rows = images[i]->rows;
      ImagePyramid& pyramid = extractors[i]->pyramid_;
      pyramid.setLevel0Rows(*images[i], rows * b / kBands, rows * (b + 1) / kBands);
      if (bandsDone[i].fetch_add(1, std::memory_order_acq_rel) != kBands - 1) continue;
      pyramid.finishLevel0();
      publish(i, 1);
      for (int l = 1; l < n[i]; ++l) {
        pyramid.buildLevel(l);
        publish(i, l + 1);
      }
    }
  };
  auto work = [&](std::size_t thread) {
    for (auto t = static_cast<std::size_t>(next++); t < tasks.size(); t = static_cast<std::size_t>(next++)) {
      const auto [i, l] = tasks[t];
      int ready = built[i].load(std::memory_order_acquire);
      for (; ready <= l; ready = built[i].load(std::memory_order_acquire)) built[i].wait(ready, std::memory_order_acquire);
      if (ready > n[i]) return;
      extractors[i]->extractLevel(l, extractors[i]->scratch_[thread]);
    }
  };
  if (!helperOwner.helper_) helperOwner.helper_ = std::make_unique<HelperThread>();
  std::exception_ptr helperError;
  helperOwner.helper_->run([&] {
    try {
      convertAndBuild();
      work(1);
    } catch (...) {
      helperError = std::current_exception();
      stopAll();  // the caller must not wait for a level this thread will never build
    }
  });
  {
    HelperThread::JoinGuard joinHelper(*helperOwner.helper_);
    try {
      convertAndBuild();
      work(0);
    } catch (...) {
      stopAll();  // before the join: the helper must not wait for a level this thread will never build
      throw;
    }
  }
  if (helperError) std::rethrow_exception(helperError);
}

void OrbExtractor::extractLevel(int l, LevelScratch& s) {
  constexpr int b = ImagePyramid::kBorder;
  std::vector<Keypoint>& keypoints = levelKeypoints_[static_cast<std::size_t>(l)];
  std::vector<OrbDescriptor>& descriptors = levelDescriptors_[static_cast<std::size_t>(l)];
  keypoints.clear();
  descriptors.clear();
  const cv::Mat& level = pyramid_.level(l);
  detectCorners(level, s);
  distribute(s, featuresPerLevel_[static_cast<std::size_t>(l)], static_cast<float>(kEdge), static_cast<float>(kEdge),
             static_cast<float>(level.cols - kEdge), static_cast<float>(level.rows - kEdge));
  if (s.selected.empty()) return;

  // Pattern points lie within 18.4 px of the keypoint, which is kEdge (19) px inside, so
  // the tests read only the interior; the blur there reads the reflected border as context.
  cv::Mat& blurred = blurred_[static_cast<std::size_t>(l)];
  blurred.create(level.rows + 2 * b, level.cols + 2 * b, CV_8UC1);
  cv::Mat target = blurred(cv::Rect(b, b, level.cols, level.rows));
  orbBlur(level, target);

  const int step = static_cast<int>(level.step);
  const int blurStep = static_cast<int>(blurred.step);
  const PyramidLevelMap toBase = pyramid_.levelMap(l);
  keypoints.reserve(s.selected.size());
  descriptors.reserve(s.selected.size());
  for (int idx : s.selected) {
    const Corner& c = s.corners[static_cast<std::size_t>(idx)];
    const int x = cvRound(c.x), y = cvRound(c.y);
    const float angle = centroidAngle(level.ptr<std::uint8_t>(y) + x, step, circleRows_.data());
    OrbDescriptor& d = descriptors.emplace_back();
    briefDescriptor(blurred.ptr<std::uint8_t>(y + b) + x + b, blurStep, angle, d);
    keypoints.push_back({toBase.toBaseX(c.x), toBase.toBaseY(c.y), angle, c.response, l});
  }
}

}  // namespace orbis
