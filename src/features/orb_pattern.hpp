// Private to src/features: the rotated-BRIEF test pattern (see orb_pattern.cpp).
#pragma once

namespace orbis::detail {
extern const int kOrbPattern[256 * 4];
}  // namespace orbis::detail
