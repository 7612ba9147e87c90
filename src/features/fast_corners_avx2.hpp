// Private to src/features: the entry points of fast_corners_avx2.cpp, compiled with -mavx2, and
// of fast_corners_avx512.cpp.
// Call them only where fastCodeAvailable(FastCode::Avx2) (fast_corners.cpp checks).
#pragma once

#include <cstddef>
#include <cstdint>

namespace orbis::detail {

// Scores of a `width` x `height` area whose top-left pixel is `image` (see fastScoreMap()).
void fastScoreRowsAvx2(const std::uint8_t* image, std::ptrdiff_t stride, int width, int height, int threshold,
                       std::uint8_t* scores, std::ptrdiff_t scoreStride);

// The same 64 pixels at a time (fast_corners_avx512.cpp, -mavx512bw): call only where
// fastCodeAvailable(FastCode::Avx512).
void fastScoreRowsAvx512(const std::uint8_t* image, std::ptrdiff_t stride, int width, int height, int threshold,
                         std::uint8_t* scores, std::ptrdiff_t scoreStride);

// Which pixels of a zero-bordered row of scores are corners, a bit each, 32 pixels a word.
void suppressRowBitsAvx2(const std::uint8_t* above, const std::uint8_t* row, const std::uint8_t* below, int width,
                         int threshold, std::uint32_t* words);

}  // namespace orbis::detail
