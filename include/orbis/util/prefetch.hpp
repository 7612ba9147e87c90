// orbis/util/prefetch.hpp — asks for an object's cache lines ahead of their use.
//
// Contract: prefetchLines(object, first, count) hints that lines first .. first + count - 1 of
// the 64-byte lines from `object`'s address will be read soon. A hint only: no effect on results,
// and no fault for any address. Used where a loop would otherwise take one miss per object, one
// after another (docs/notes/2026-11-29-speed-slot-bits.md).
#pragma once

namespace orbis {

// Hints that 64-byte lines first .. first + count - 1 from `object` will be read soon.
inline void prefetchLines(const void* object, int first, int count) {
  const char* bytes = static_cast<const char*>(object);
  for (int line = first; line < first + count; ++line) __builtin_prefetch(bytes + 64 * line);
}

}  // namespace orbis
