// tests/map_file_bytes.hpp — a map file's bytes made consistent again after a test (or the fuzzer)
// has changed them, as a writer would leave them (io/map_file.hpp): the declared total size at
// byte 16 and the checksum of everything before the last 8 bytes in those bytes. Without it,
// nearly every change stops at the checksum and the checks behind it are never reached.
#pragma once

#include <cstdint>
#include <cstring>

#include "orbis/bow/vocabulary_file.hpp"

namespace orbis::test {

inline constexpr std::size_t kMapFileSizeOffset = 16;
inline constexpr std::size_t kMapFileMinimumResealed = 160;  // shorter: left as it is

// Bytes: a contiguous container of char or std::uint8_t.
template <class Bytes>
void resealMapFile(Bytes& bytes) {
  if (bytes.size() < kMapFileMinimumResealed) return;
  const std::uint64_t size = bytes.size();
  std::memcpy(bytes.data() + kMapFileSizeOffset, &size, sizeof size);
  const std::uint64_t sum = bow::checksum64(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &sum, sizeof sum);
}

}  // namespace orbis::test
