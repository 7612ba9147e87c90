// retainFreedMemory: on glibc both settings take, and a block far above malloc's default mmap
// threshold then comes from the heap (not a fresh mapping), so freeing it keeps it for reuse.
#include <gtest/gtest.h>

#include <cstdlib>

#include "orbis/util/allocator.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace orbis {
namespace {

#if defined(__GLIBC__)
TEST(RetainFreedMemory, LargeBlocksComeFromTheHeapAndStayAfterFree) {
  ASSERT_TRUE(retainFreedMemory());
  EXPECT_TRUE(retainFreedMemory());  // again: no harm
  constexpr std::size_t kBlock = 8u << 20;  // 8 MiB: mmapped under glibc's defaults
  const std::size_t mappedBefore = mallinfo2().hblkhd;
  void* block = std::malloc(kBlock);
  ASSERT_NE(block, nullptr);
  static_cast<volatile char*>(block)[kBlock - 1] = 1;
  EXPECT_EQ(mallinfo2().hblkhd, mappedBefore);  // not a mapping of its own
  std::free(block);
  EXPECT_GE(mallinfo2().fordblks, kBlock);  // kept as free heap memory, not given back
}
#else
TEST(RetainFreedMemory, ReportsThatItDoesNotApplyWithoutGlibc) { EXPECT_FALSE(retainFreedMemory()); }
#endif

}  // namespace
}  // namespace orbis
