// tests/adapters/rendered_sequence.hpp — a small rendered sequence for the adapter tests: one slow
// loop of 150 frames at 320x240 (consecutive frames overlap as a real camera's do), so SLAM runs
// on its first few dozen frames.
#pragma once

#include <cstdint>
#include <filesystem>

#include "orbis/synth/writers.hpp"

namespace orbis::test {

inline synth::SynthWriteResult renderSmallLoop(synth::SynthLayout layout, const std::filesystem::path& dir,
                                               std::uint64_t seed, double baseline = 0.1) {
  synth::SynthOptions o;
  o.frames = 150;
  o.width = 320;
  o.height = 240;
  o.fx = 250.0;
  o.baseline = baseline;
  o.seed = seed;
  o.threads = 2;
  synth::SyntheticSequence sequence(o);
  return synth::writeSynthSequence(sequence, layout, dir);
}

}  // namespace orbis::test
