// tests/map_file_bytes.hpp — a map file's bytes made consistent again after a test (or the fuzzer)
// has changed them, as a writer would leave them (io::sealMapFileBytes: the declared total size
// and the trailer's checksum). Without it, nearly every change stops at the checksum and the
// checks behind it are never reached.
#pragma once

#include <cstddef>
#include <span>

#include "orbis/io/map_file.hpp"

namespace orbis::test {

inline constexpr std::size_t kMapFileMinimumResealed = 160;  // shorter: left as it is

// Bytes: a contiguous container of char or std::uint8_t.
template <class Bytes>
void resealMapFile(Bytes& bytes) {
  if (bytes.size() < kMapFileMinimumResealed) return;
  sealMapFileBytes(std::span<char>(reinterpret_cast<char*>(bytes.data()), bytes.size()));
}

}  // namespace orbis::test
