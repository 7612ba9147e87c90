// orbis/util/allocator.hpp — keeps the memory that bundle adjustment frees inside the process.
//
// Contract: retainFreedMemory() raises glibc malloc's mmap threshold to its maximum (32 MiB) and
// its trim threshold to 256 MiB, process-wide, so that the large buffers every bundle adjustment
// allocates and frees are reused instead of being unmapped and faulted in again page by page; it
// returns true when both settings took (glibc), false elsewhere (other C libraries: nothing
// changes). Calling it again does no harm. The cost is that the process keeps its peak heap
// instead of returning it to the system. A SLAM system (SlamCore, and so Slam, `orbis run`,
// bench_slam and the Python classes) calls it on construction unless
// SlamOptions::retainFreedMemory is false. Why: docs/notes/2026-11-27-speed-mapping-cpu.md.
#pragma once

namespace orbis {

// Makes glibc keep freed memory for reuse (see the contract above); true when it applied.
bool retainFreedMemory();

}  // namespace orbis
