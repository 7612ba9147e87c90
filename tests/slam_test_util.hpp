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
  else if constexpr (std::is_same_v<Sensor, Monocular>) return seq.camera();
  else return RectifiedStereoCamera<double>(seq.camera(), baseline);
}

template <class Sensor>
typename Sensor::Input syntheticInput(const synth::SynthFrame& f, double timestamp) {
  if constexpr (std::is_same_v<Sensor, Rgbd>) return RgbdInput{timestamp, f.left, f.depth};
  else if constexpr (std::is_same_v<Sensor, Monocular>) return MonocularInput{timestamp, f.left};
  else return StereoInput{timestamp, f.left, f.right};
}

// Which images a sensor needs rendered: (right, depth).
template <class Sensor>
constexpr bool needsRight() { return Sensor::kKind == SensorKind::Stereo; }
template <class Sensor>
constexpr bool needsDepth() { return Sensor::kDepthFromSensor; }

// The length of a trajectory's path, metres.
inline double pathLength(const Trajectory& t) {
  double len = 0;
  for (std::size_t i = 1; i < t.size(); ++i) len += (t[i].pose.translation() - t[i - 1].pose.translation()).norm();
  return len;
}

// Same timestamps and bit-identical poses.
inline bool identical(const Trajectory& a, const Trajectory& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].t != b[i].t || a[i].pose.matrix() != b[i].pose.matrix()) return false;
  return true;
}

}  // namespace orbis::test
