// orbis/synth/rng.hpp — the portable random source behind every synthetic scene and image.
//
// Contract: SynthRng is a SplitMix64 generator whose uniform() and normal() are defined here
// bit for bit (the standard library's distributions differ between implementations), so a
// seed gives the same textures, noise and trajectories on every platform and compiler.
// mixSeed() derives independent streams (per texture, per frame, per camera) from one seed.
#pragma once

#include <cmath>
#include <cstdint>

namespace orbis::synth {

// SplitMix64: a small, fast generator whose sequence is the same on every platform (rendered data
// must not depend on the standard library).
class SynthRng {
 public:
  // A generator from a seed.
  explicit SynthRng(std::uint64_t seed) : state_(seed) {}

  // The next 64 random bits.
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [lo, hi]; the modulo bias is below 2^-40 for the ranges used here.
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  // Standard normal by Box–Muller, one value per call (the pair's twin is kept).
  double normal() {
    if (hasSpare_) {
      hasSpare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]: log stays finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double a = 6.283185307179586 * u2;
    spare_ = r * std::sin(a);
    hasSpare_ = true;
    return r * std::cos(a);
  }

 private:
  std::uint64_t state_;
  double spare_ = 0.0;
  bool hasSpare_ = false;
};

// A seed for an independent stream: the same (seed, a, b) always gives the same value.
inline std::uint64_t mixSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0) {
  SynthRng rng(seed ^ (a * 0xD1B54A32D192ED03ULL) ^ (b * 0x8CB92BA72F3D8DD7ULL));
  rng.next();
  return rng.next();
}

}  // namespace orbis::synth
