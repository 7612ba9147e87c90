// Helpers shared by the end-to-end SLAM tests (system/, loop/): the shipped vocabulary loaded
// once per process, the camera a synthetic sequence is rendered with, and one frame's input.
#pragma once

#include <memory>
#include <type_traits>

#include "orbis/synth/sequence.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/system/slam.hpp"

namespace orbis::test {

inline std::shared_ptr<const OrbVocabulary> sharedVocabulary() {
  static auto voc = std::make_shared<const OrbVocabulary>(OrbVocabulary::load(defaultVocabularyPath()));
  return voc;
}

// One loop around the room at low resolution with image noise: enough drift for the loop to
// matter, small enough to render and track in seconds.
inline synth::SynthOptions loopSequence(std::uint64_t seed) {
  synth::SynthOptions o;
  o.frames = 300;  // frames per loop
  o.width = 320;
  o.height = 240;
  o.fx = 250;
  o.noiseSigma = 4.0;
  o.seed = seed;
  o.threads = 2;
  return o;
}

// Synthetic depth maps are in metres (CV_32F), so the RGB-D camera's depth factor is 1.
template <class Sensor>
typename Sensor::Camera syntheticCamera(const synth::SyntheticSequence& seq, double baseline) {
  if constexpr (std::is_same_v<Sensor, Rgbd>) return RgbdCamera<double>(seq.camera(), baseline, 1.0);
  else return RectifiedStereoCamera<double>(seq.camera(), baseline);
}

template <class Sensor>
typename Sensor::Input syntheticInput(const synth::SynthFrame& f, double timestamp) {
  if constexpr (std::is_same_v<Sensor, Rgbd>) return RgbdInput{timestamp, f.left, f.depth};
  else return StereoInput{timestamp, f.left, f.right};
}

}  // namespace orbis::test
