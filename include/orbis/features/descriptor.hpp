// orbis/features/descriptor.hpp — the 256-bit binary ORB descriptor and its Hamming distance.
//
// Contract: OrbDescriptor is 32 bytes stored as four 64-bit words (trivially copyable, 8-byte
// aligned); hammingDistance uses the hardware popcount when the compiler enables it.
// DescriptorDistance is the one concept of a distance policy; HammingDistance is ORB's.
#pragma once

#include <array>
#include <bit>
#include <concepts>
#include <cstdint>
#include <cstring>

namespace orbis {

// A 256-bit ORB (rotated BRIEF) descriptor, as four 64-bit words.
struct OrbDescriptor {
  // @{
  // Its size in bits and bytes.
  static constexpr int kBits = 256;
  static constexpr int kBytes = 32;
  // @}
  // The bits, little-endian within each word.
  std::array<std::uint64_t, 4> words{};

  // @{
  // The 32 bytes, in OpenCV's descriptor-row order.
  const std::uint8_t* bytes() const { return reinterpret_cast<const std::uint8_t*>(words.data()); }
  std::uint8_t* bytes() { return reinterpret_cast<std::uint8_t*>(words.data()); }
  // @}
  // @{
  // Reads or sets bit i.
  bool bit(int i) const { return (words[static_cast<std::size_t>(i >> 6)] >> (i & 63)) & 1u; }
  void setBit(int i, bool v) {
    const std::uint64_t m = std::uint64_t{1} << (i & 63);
    auto& w = words[static_cast<std::size_t>(i >> 6)];
    w = v ? (w | m) : (w & ~m);
  }
  // @}
  // From the 32 bytes of an OpenCV descriptor row (CV_8U, 32 columns).
  static OrbDescriptor fromBytes(const std::uint8_t* src) {
    OrbDescriptor d;
    std::memcpy(d.words.data(), src, kBytes);
    return d;
  }
  friend bool operator==(const OrbDescriptor&, const OrbDescriptor&) = default;
};

// The number of differing bits (POPCNT where the build enables it).
inline int hammingDistance(const OrbDescriptor& a, const OrbDescriptor& b) {
  return std::popcount(a.words[0] ^ b.words[0]) + std::popcount(a.words[1] ^ b.words[1]) +
         std::popcount(a.words[2] ^ b.words[2]) + std::popcount(a.words[3] ^ b.words[3]);
}

// A distance policy between descriptors of type D, what the matchers and the vocabulary are
// templated on: default-constructible (both take it by value, defaulted to {}) and giving an
// integer distance, smaller meaning more alike.
template <class P, class D>
concept DescriptorDistance = std::default_initializable<P> && requires(const P p, const D& a) {
  { p(a, a) } -> std::convertible_to<int>;
};

// The distance policy of binary descriptors.
struct HammingDistance {
  // @{
  // The descriptor type, its distance type and the largest distance.
  using Descriptor = OrbDescriptor;
  using Distance = int;
  static constexpr int kMax = OrbDescriptor::kBits;
  // @}
  // The Hamming distance of a and b.
  int operator()(const OrbDescriptor& a, const OrbDescriptor& b) const { return hammingDistance(a, b); }
};
static_assert(DescriptorDistance<HammingDistance, OrbDescriptor>);

}  // namespace orbis
