// orbis/synth/writers.hpp — writes synthetic sequences in the benchmarks' on-disk layouts.
//
// Contract: writeSynthSequence() renders every frame of a SyntheticSequence once and stores it
// so the dataset adapters read it exactly like a download:
//   Tum    rgb/<t>.png (8-bit grey), depth/<t>.png (16-bit, metres x 5000, 0 = invalid),
//          rgb.txt, depth.txt (same instants), groundtruth.txt (TUM, T_wc in the scene frame);
//   Euroc  mav0/cam0, mav0/cam1: data/<ns>.png, data.csv, sensor.yaml (pinhole, zero
//          radial-tangential distortion, T_BS identity for cam0 and a pure +baseline x shift
//          for cam1: already rectified); mav0/state_groundtruth_estimate0/data.csv (body = cam0);
//   Kitti  sequences/00/image_0, image_1 (<6-digit index>.png), times.txt (seconds from frame
//          0), calib.txt (P0, P1 with P1[0,3] = -fx * baseline), poses/00.txt (T_wc relative
//          to frame 0, as KITTI does).
// Each layout also gets settings.yaml (ORB-SLAM2 keys, plus Sensor: rgbd for Tum, stereo
// otherwise, and System.seed) and settings_mono.yaml (the same camera as a monocular one) in
// its root directory. Existing files are overwritten; a file that cannot be written throws
// orbis::Error naming it.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "orbis/synth/sequence.hpp"

namespace orbis::synth {

// The dataset layout a rendered sequence is written in.
enum class SynthLayout { Tum, Euroc, Kitti };

// "tum", "euroc" or "kitti"; anything else throws orbis::Error(source).
SynthLayout parseSynthLayout(std::string_view name, const std::string& source = "layout");
// "tum", "euroc" or "kitti".
std::string_view toString(SynthLayout layout);

// What writeSynthSequence wrote.
struct SynthWriteResult {
  std::filesystem::path root;          // the layout's root (outDir)
  std::filesystem::path groundTruth;   // the ground-truth trajectory file
  std::filesystem::path settings;      // settings.yaml
  std::filesystem::path settingsMono;  // settings_mono.yaml
  // @{
  // Frames written, and how many of them black.
  int frames = 0;
  int blackFrames = 0;
  // @}
  double renderSeconds = 0.0;          // wall time spent rendering (not writing)
  double renderCpuSeconds = 0.0;       // CPU time of the same, summed over threads
  // Wall time of the whole write.
  double totalSeconds = 0.0;
};

// onFrame(done) is called after each frame is written (for a progress bar).
SynthWriteResult writeSynthSequence(SyntheticSequence& sequence, SynthLayout layout,
                                    const std::filesystem::path& outDir,
                                    const std::function<void(int)>& onFrame = {});

// sensor: "mono", "stereo" or "rgbd".
void writeSynthSettings(const std::filesystem::path& file, const SyntheticSequence& sequence,
                        std::string_view sensor);

}  // namespace orbis::synth
