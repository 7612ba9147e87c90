// orbis/system/dataset_runner.hpp — SLAM over a whole sequence or stream, with its outputs.
//
// Contract: runSource reads frames one after another from a FrameSource (a dataset, a video, an
// image folder, a live camera: adapters/frame_source.hpp); runDataset is runSource over a
// dataset read in order. The run picks the compile-time sensor configuration once from the
// source's sensor (Slam<Stereo>, Slam<Rgbd> or
// Slam<Monocular>), tracks every frame and writes, into options.outDir: trajectory.txt (TUM,
// camera-to-world, every tracked frame), trajectory_maps.txt (per line of it: timestamp, the
// map it was tracked in, the map holding it now), keyframes.txt (TUM), report.json (frame counts,
// keyframes, map points, the atlas's maps and merges, per-stage timing in ms: mean/median/p95, and the ATE of all frames and
// of the keyframes when the dataset has ground truth, Sim(3)-aligned for monocular, else SE(3)), map.ply (map points) and overview.png (top view); for RGB-D, optionally a
// dense cloud back-projected from the final keyframes' depth maps (RunOptions::denseCloud).
// A frame that cannot be read or tracked is reported and survived; outputs computed so far are still written if a
// later frame throws. The camera comes from the settings file when given (ORB-SLAM2 YAML),
// else from the dataset's own calibration; a source without calibration and no settings file
// throws orbis::Error saying how to get one. RunOptions::resizeWidth (or the settings key
// Camera.newWidth) scales every image and the intrinsics together before extraction; frames of
// another size than the settings' Camera.width/height but the same aspect scale the intrinsics
// too (with a warning), another aspect throws. RunOptions::stopRequested (a signal flag) is
// checked every frame: the run ends there, writes every output and marks the report
// interrupted. A live source's dropped frames, the capture-to-pose latency of every frame
// (median, p95) and why a source ended early go into the report. RunOptions::observer, when set, sees every frame and
// takes map snapshots while the run lasts, and gets the final map after shutdown.
// RunOptions::realtime feeds the frames of a source that is not live at the rate they were recorded:
// each frame no earlier than its timestamp's offset from the first frame's (on the steady clock,
// from when the first was fed); a frame tracking is already late for is fed at once, never
// skipped, and the run does not slow down to catch up. Without it, frames are fed as fast as
// tracking takes them.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "orbis/adapters/dataset.hpp"
#include "orbis/adapters/frame_source.hpp"
#include "orbis/system/slam.hpp"

namespace orbis {

// What orbis run does, as options of runDataset.
struct RunOptions {
  // ORB-SLAM2 settings file (empty: the dataset's calibration).
  std::optional<std::filesystem::path> settings;
  // Vocabulary file (defaultVocabularyPath(): the shipped one).
  std::filesystem::path vocabulary;
  // Output folder.
  std::filesystem::path outDir = "out";
  // Run the stages inline in a fixed order (bit-identical runs).
  bool deterministic = false;
  // Localisation only: no keyframes or points are added.
  bool localisationOnly = false;
  // Whether loops are closed.
  bool loopClosing = true;
  std::optional<std::filesystem::path> denseCloud;  // RGB-D: back-projected keyframe depth maps
  std::size_t maxFrames = 0;                        // 0: all
  // Show a progress bar on a terminal.
  bool progress = true;
  bool realtime = false;  // feed each frame at its timestamp (relative to the first), not as fast as tracking goes
  std::optional<std::filesystem::path> loadMap;  // map file to localise in (io/map_file.hpp)
  std::optional<std::filesystem::path> saveMap;  // where to save the final map
  SlamObserver* observer = nullptr;              // e.g. a live viewer (slam_observer.hpp); not owned
  bool stats = false;  // diagnosis: outDir/stats.jsonl, one line per frame and per keyframe (StageTimer events)
  // @{
  // The atlas (docs/guide/atlas.md): off keeps ORB-SLAM2's single map; when to open a new map.
  bool atlas = true;
  int newMapAfterLostFrames = 10;
  double newMapAfterLostSeconds = 0.3;
  // @}
  int resizeWidth = 0;  // > 0: images and intrinsics scaled to this width first (wins over Camera.newWidth)
  std::function<bool()> stopRequested;  // true: end the run now, outputs written, report interrupted
  // Ground truth (any trajectory format readTrajectory detects) for a source that has none, matched
  // to the frames by timestamp (a video run with SourceOptions::timesFile gets the images' times).
  std::optional<std::filesystem::path> groundTruth;
};

// Capture-to-pose latency of the frames tracked, milliseconds.
struct LatencyStats {
  // Frames measured.
  std::size_t count = 0;
  // @{
  // Median, 95th percentile and largest latency.
  double medianMs = 0, p95Ms = 0, maxMs = 0;
  // @}
};

// What a run did: its counters, timing, accuracy and warnings (report.json).
struct RunReport {
  // @{
  // The sequence folder and the sensor it ran as.
  std::string dataset, sensor;
  // @}
  // Frames, keyframes, points and initialisation.
  SlamStats stats;
  // Per-stage timing.
  std::vector<StageStats> timing;
  std::optional<double> ateRmse;  // of every tracked frame: metres (monocular: ground-truth units)
  // Poses matched for the ATE.
  std::size_t ateMatched = 0;
  std::string ateAlignment = "se3";         // "sim3" for monocular: its map's scale is arbitrary
  std::optional<double> ateKeyFramesRmse;   // the same for the keyframe trajectory
  // Keyframes matched for the keyframe ATE.
  std::size_t ateKeyFramesMatched = 0;
  double pathLength = 0;          // of the ground truth over the matched poses, metres
  // Warnings, in order.
  std::vector<std::string> warnings;
  // Wall time, seconds.
  double seconds = 0;
  std::size_t keyFramesLoaded = 0;  // from RunOptions::loadMap
  std::optional<bool> loadedMapMetricScale;  // from its file; false: the map's unit is arbitrary
  std::size_t densePoints = 0;      // voxels in RunOptions::denseCloud
  // @{
  // Relocalisation attempts and successes.
  std::size_t relocalisationAttempts = 0, relocalisations = 0;
  // @}
  // Loops closed, in order; a monocular one carries its Sim(3) scale: the scale drift it corrected.
  std::vector<LoopClosureEvent> loopClosures;
  // @{
  // The atlas: every map opened (report.json "maps"), the merges in order, and per tracked frame
  // the map it was tracked in (trajectory_maps.txt).
  std::vector<AtlasMapInfo> maps;
  std::vector<MapMergeEvent> merges;
  std::vector<std::uint32_t> frameMaps;
  // @}
  // @{
  // The source: whether it was live, frames it dropped (newest frame wins), why it ended early
  // (empty: it ended normally), the capture-to-pose latency, and the frame sizes delivered and tracked.
  bool live = false;
  std::size_t droppedFrames = 0;
  std::string endReason;
  LatencyStats latency;
  int inputWidth = 0, inputHeight = 0;  // of the frames as delivered
  int resizedWidth = 0, resizedHeight = 0;  // as tracked, when scaled (0: not scaled)
  // @}
  bool interrupted = false;  // RunOptions::stopRequested ended the run
};

// Runs SLAM over the frames of any source (a dataset, a video, an image folder, a live camera) and
// writes trajectory.txt, keyframes.txt, report.json, map.ply and overview.png into options.outDir
// (and stats.jsonl, the dense cloud and the map when asked).
RunReport runSource(FrameSource& source, const RunOptions& options);
// Runs SLAM over a dataset read in order (runSource over makeDatasetSource).
RunReport runDataset(DatasetReader& dataset, const RunOptions& options);

// The vocabulary shipped with orbis: the source tree's vocabulary/ when run from a build, else
// the installed share/orbis/vocabulary/. Throws orbis::Error when none is found.
std::filesystem::path defaultVocabularyPath();

}  // namespace orbis
