#include "orbis/util/allocator.hpp"

#include <cstdlib>  // defines __GLIBC__ under glibc, which the #if below tests

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace orbis {

bool retainFreedMemory() {
#if defined(__GLIBC__)
  // glibc caps the mmap threshold at 32 MiB on 64-bit systems (DEFAULT_MMAP_THRESHOLD_MAX).
  constexpr int kMmapThreshold = 32 << 20;
  constexpr int kTrimThreshold = 256 << 20;
  const bool mmap = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  const bool trim = mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1;
  return mmap && trim;
#else
  return false;
#endif
}

}  // namespace orbis
