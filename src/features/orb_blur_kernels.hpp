// Private to src/features: the entry points of orb_blur_avx2.cpp (-mavx2) and orb_blur_avx512.cpp
// (-mavx512bw), the blur's integer rows (orb_blur_kernel.inc). Call them only where the CPU has
// the instruction set and the build compiled them (orb_blur.cpp checks).
#pragma once

#include <cstddef>
#include <cstdint>

namespace orbis::detail {

// The blur of a `width` x `height` area at `src` (3 valid pixels around it) into `dst`; width at
// least 16 (AVX2) or 32 (AVX-512); `sums` holds width + 6 entries.
void blurRowsAvx2(const std::uint8_t* src, std::ptrdiff_t srcStride, int width, int height, std::uint8_t* dst,
                  std::ptrdiff_t dstStride, std::int16_t* sums);
void blurRowsAvx512(const std::uint8_t* src, std::ptrdiff_t srcStride, int width, int height, std::uint8_t* dst,
                    std::ptrdiff_t dstStride, std::int16_t* sums);

}  // namespace orbis::detail
