// orbis run: SLAM on a dataset sequence (TUM RGB-D, EuRoC, KITTI layouts), a video, an image
// folder or a live camera.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>

#include "command.hpp"
#include "run_sources.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"
#include "orbis/util/warnings.hpp"
#ifdef ORBIS_HAS_VIEWER
#include "orbis/viewer/live_viewer.hpp"
#endif

namespace orbis::cli {
namespace {

// Before the run, so an unwritable --out fails at once rather than after the sequence.
void createOutputFolder(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw Error(dir.string(), "", "cannot create the output folder (" + (ec ? ec.message() : "not a folder") + ")");
}

// A run that tracked nothing has failed, whatever it wrote: say why, and exit non-zero.
void requireSomethingTracked(const std::string& root, std::optional<std::size_t> frames, const RunReport& r) {
  if (frames && *frames == 0) throw Error(root, "", "the sequence lists no frame: nothing to run");
  if (r.stats.frames == 0 && !r.endReason.empty()) throw Error(root, "", "no frame processed: " + r.endReason);
  if (r.stats.frames == 0)
    throw Error(root, "", "none of the " + (frames ? std::to_string(*frames) + " " : std::string()) +
                              "frames could be processed (every one was skipped; the warnings above say why)");
  if (r.stats.tracked == 0)
    throw Error(root, "", "none of the " + std::to_string(r.stats.frames) +
                              " frames processed was tracked: check the camera calibration (--settings FILE), "
                              "the vocabulary (--vocab) and that the images are not blank");
}

// `--viewer` may stand without its PORT: give it the default.
std::vector<std::string> withViewerPort(std::vector<std::string> args) {
  for (std::size_t i = 0; i < args.size(); ++i)
    if (args[i] == "--viewer" && (i + 1 == args.size() || args[i + 1].rfind("--", 0) == 0))
      args[i] = "--viewer=8080";
  return args;
}

void printReport(const RunReport& r, const RunOptions& options, bool json);

#ifdef ORBIS_HAS_VIEWER
int viewerPort(const ArgParser& p) {
  const long port = p.getInt("--viewer");
  if (port < 1 || port > 65535) throw Error("argument --viewer", "", "expects a port between 1 and 65535");
  return static_cast<int>(port);
}
#endif

int runCommand(const std::vector<std::string>& rawArgs) {
  const std::vector<std::string> args = withViewerPort(rawArgs);
  ArgParser p("orbis run tum|euroc|kitti|kitti-raw PATH | video FILE|URL | images DIR | camera [N|/dev/videoN|PIPELINE]\n"
              "           [--settings FILE] [--vocab FILE] [--out DIR] [--deterministic] [--realtime]",
              "Runs SLAM over a dataset sequence, a video, an image folder or a live camera and writes\n"
              "DIR/trajectory.txt, keyframes.txt, report.json, map.ply and overview.png. Stereo sequences\n"
              "(EuRoC, KITTI) run as stereo, TUM as RGB-D; videos, folders and cameras as monocular unless\n"
              "--stereo, --right or --depth say otherwise, and need --settings (their camera's calibration).\n"
              "kitti-raw PATH is a raw drive folder (image_00, image_01, oxts) with the calib_*.txt files beside it.\n"
              "Ctrl-C ends a run cleanly: every output is written, the report marked interrupted, exit status 130.");
  p.positional("DATASET", "tum, euroc, kitti or kitti-raw (the on-disk layout), or video, images or camera")
      .positional("PATH", "the sequence folder; the video file, URL or GStreamer pipeline; the image folder; the camera (index, /dev/videoN or pipeline, default 0)", false)
      .option("--settings", "FILE", "ORB-SLAM2 settings YAML (camera, ORBextractor.*); default: the dataset's calibration (required for video, images and camera)")
      .option("--vocab", "FILE", "vocabulary (orbis binary); default: the shipped one")
      .option("--out", "DIR", "output folder", "out")
      .option("--sensor", "KIND", "read the dataset as mono, stereo or rgbd (default: its own sensor)")
      .option("--sequence", "NN", "KITTI: the sequence to run when PATH holds several (sequences/NN)")
      .option("--max-frames", "N", "process at most N frames (0: all)", "0")
      .option("--dense", "FILE", "RGB-D: write a dense coloured cloud (PLY, 1 cm voxels) back-projected from the final keyframes' depth maps")
      .flag("--realtime", "feed each frame at its timestamp (counted from the first), as a live camera would; a frame tracking is late for goes at once (default: as fast as tracking goes)")
      .flag("--deterministic", "run the stages inline in a fixed order: identical input gives an identical trajectory")
      .flag("--localize", "localisation only: track against the map without mapping")
      .option("--load-map", "FILE", "start from a saved map (same sensor, camera and vocabulary) and relocalise in it")
      .option("--save-map", "FILE", "save the final map (keyframes, points, graphs) for a later --load-map")
      .flag("--no-loop", "disable loop closing")
      .flag("--single-map", "ORB-SLAM2's single map: stay lost until relocalised instead of starting a new map of the atlas")
      .option("--new-map-after", "FRAMES:SECONDS", "start a new map once relocalisation failed on FRAMES frames spanning SECONDS", "10:0.3")
      .flag("--json", "print the report as JSON on standard output")
      .flag("--stats", "write DIR/stats.jsonl: per-frame tracking and per-keyframe mapping counters (diagnosis)")
      .option("--fps", "HZ", "video, images, camera: the frame rate that times the frames (frame i at i/HZ; overrides a video's own times)")
      .option("--times", "FILE", "video, images: one timestamp per frame (first column; seconds or nanoseconds), e.g. the rgb.txt the frames came from")
      .option("--groundtruth", "FILE", "a trajectory (TUM, KITTI or EuRoC) to compute the ATE against, matched to the frames by timestamp")
      .option("--resize", "WIDTH", "scale every image and the intrinsics to this width before extraction (default: Camera.newWidth, else none)")
      .option("--stereo", "PACKING", "video, images, camera: each frame holds both views, side-by-side or top-bottom")
      .option("--right", "PATH", "video, images: the right camera's video or folder (stereo from two sources, frame i with frame i)")
      .option("--depth", "DIR", "images: the depth folder (16-bit PNG) paired with the colour folder PATH by timestamp (RGB-D)")
      .option("--stall", "SECONDS", "a live source that delivers nothing for this long ends the run", "5")
      .option("--viewer", "[PORT]", "serve a live view of the run at http://127.0.0.1:PORT/ (default port 8080)")
      .flag("--viewer-wait", "with --viewer: keep serving the finished run until Ctrl-C");
  if (!p.parse(args)) return 0;
  const bool stream = isStreamSourceKind(p.pos(0));
  std::unique_ptr<DatasetReader> dataset;
  std::unique_ptr<FrameSource> source;
  if (stream) {
    source = openStreamSource(p.pos(0), p);
  } else {
    const DatasetKind kind = parseDatasetKind(p.pos(0), "argument DATASET");
    if (p.positionalCount() < 2) throw Error("arguments", "", "missing PATH\nusage: orbis run " + p.pos(0) + " PATH [options]");
    for (const char* streamOnly : {"--fps", "--times", "--stereo", "--right", "--depth"})
      if (p.has(streamOnly))
        throw Error(std::string("argument ") + streamOnly, "", "applies to video, images and camera, not to a dataset");
    DatasetOptions datasetOptions;
    datasetOptions.tolerateBadFrames = true;  // a bad frame is reported and skipped, not the end of the run
    if (auto s = p.getOptional("--sequence")) datasetOptions.kittiSequence = *s;
    if (auto s = p.getOptional("--sensor")) datasetOptions.sensor = parseSensorKind(*s, "argument --sensor");
    dataset = openDataset(kind, p.pos(1), datasetOptions);
  }
  RunOptions options;
  if (auto g = p.getOptional("--groundtruth")) options.groundTruth = *g;
  if (p.has("--resize")) {
    const long width = p.getInt("--resize");
    if (width < 16) throw Error("argument --resize", "", "expects a width of at least 16 pixels");
    options.resizeWidth = static_cast<int>(width);
  }
  if (auto s = p.getOptional("--settings")) options.settings = *s;
  options.vocabulary = p.has("--vocab") ? std::filesystem::path(p.get("--vocab")) : defaultVocabularyPath();
  options.outDir = p.get("--out");
  createOutputFolder(options.outDir);
  options.deterministic = p.has("--deterministic");
  options.realtime = p.has("--realtime");
  options.stats = p.has("--stats");
  options.localisationOnly = p.has("--localize");
  options.loopClosing = !p.has("--no-loop");
  options.atlas = !p.has("--single-map");
  {
    const std::string after = p.get("--new-map-after");
    const auto colon = after.find(':');
    try {
      options.newMapAfterLostFrames = std::stoi(after.substr(0, colon));
      if (colon != std::string::npos) options.newMapAfterLostSeconds = std::stod(after.substr(colon + 1));
    } catch (const std::exception&) {
      throw Error("argument --new-map-after", "", "expected FRAMES:SECONDS, e.g. 10:0.3, not '" + after + "'");
    }
    if (options.newMapAfterLostFrames < 1 || options.newMapAfterLostSeconds < 0)
      throw Error("argument --new-map-after", "", "expected at least 1 frame and 0 or more seconds");
  }
  if (auto d = p.getOptional("--dense")) options.denseCloud = *d;
  if (auto m = p.getOptional("--load-map")) options.loadMap = *m;
  if (auto m = p.getOptional("--save-map")) options.saveMap = *m;
  const long maxFrames = p.getInt("--max-frames");
  if (maxFrames < 0) throw Error("argument --max-frames", "", "must be 0 or positive");
  options.maxFrames = static_cast<std::size_t>(maxFrames);
  options.progress = !p.has("--json");

#ifdef ORBIS_HAS_VIEWER
  std::unique_ptr<LiveViewer> viewer;
  if (p.has("--viewer")) {
    viewer = std::make_unique<LiveViewer>(ViewerOptions{.port = viewerPort(p)});
    std::fprintf(stderr, "viewer: %s\n", viewer->url().c_str());
    options.observer = viewer.get();
  }
#else
  if (p.has("--viewer")) throw Error("argument --viewer", "", "this orbis was built without the viewer (ORBIS_BUILD_VIEWER)");
#endif
  catchInterrupts();
  options.stopRequested = [] { return interruptRequested(); };
  const RunReport r = dataset ? runDataset(*dataset, options) : runSource(*source, options);
  printReport(r, options, p.has("--json"));
#ifdef ORBIS_HAS_VIEWER
  if (viewer) {
    const ViewerStats v = viewer->stats();
    std::fprintf(stderr, "viewer: %zu frame and %zu map messages, %.1f MB, %.3f s CPU on its publisher thread over %.1f s\n",
                 v.frameMessages, v.mapMessages, 1e-6 * static_cast<double>(v.bytes), v.publisherCpuSeconds, r.seconds);
  }
  if (viewer && p.has("--viewer-wait")) {
    std::fprintf(stderr, "viewer: serving the finished run at %s; Ctrl-C to stop\n", viewer->url().c_str());
    waitUntilInterrupted();
  }
#endif
  if (r.interrupted) {
    std::fprintf(stderr, "interrupted: the outputs computed so far are in %s\n", options.outDir.string().c_str());
    return 130;
  }
  if (dataset) requireSomethingTracked(dataset->root().string(), dataset->size(), r);
  else requireSomethingTracked(source->name(), std::nullopt, r);
  if (!r.endReason.empty()) std::fprintf(stderr, "warning: the source ended early: %s\n", r.endReason.c_str());
  return 0;
}

void printReport(const RunReport& r, const RunOptions& options, bool json) {
  if (json) {
    std::ifstream in(options.outDir / "report.json");
    std::printf("%s", std::string(std::istreambuf_iterator<char>(in), {}).c_str());
    return;
  }
  std::printf("dataset        %s (%s)\n", r.dataset.c_str(), r.sensor.c_str());
  std::printf("frames         %zu  tracked %zu  lost %zu\n", r.stats.frames, r.stats.tracked, r.stats.lost);
  std::printf("map            %zu keyframes, %zu points\n", r.stats.keyFrames, r.stats.mapPoints);
  if (!r.stats.initialisationWaits.empty() || !r.stats.initialisedAtFrame) {
    std::string waits;
    for (const auto& [reason, frames] : r.stats.initialisationWaits)
      waits += (waits.empty() ? "" : ", ") + reason + " " + std::to_string(frames);
    if (r.stats.initialisedAtFrame) std::printf("initialised    at frame %llu", static_cast<unsigned long long>(*r.stats.initialisedAtFrame));
    else std::printf("initialised    never");
    std::printf("%s%s%s\n", waits.empty() ? "" : " (frames waiting: ", waits.c_str(), waits.empty() ? "" : ")");
  }
  if (r.maps.size() > 1) {
    std::size_t live = 0;
    for (const AtlasMapInfo& m : r.maps) live += m.merged ? 0 : 1;
    std::printf("atlas          %zu maps opened, %zu merges, %zu maps left\n", r.maps.size(), r.merges.size(), live);
  }
  if (options.loadMap || r.relocalisationAttempts)
    std::printf("relocalised    %zu of %zu attempts; %zu keyframes loaded%s\n", r.relocalisations,
                r.relocalisationAttempts, r.keyFramesLoaded,
                !r.loadedMapMetricScale ? "" : *r.loadedMapMetricScale ? " (metric scale)" : " (scale arbitrary)");
  if (options.denseCloud && r.densePoints)
    std::printf("dense cloud    %zu points in %s\n", r.densePoints, options.denseCloud->string().c_str());
  if (r.live || r.droppedFrames)
    std::printf("live           %zu frames dropped (newest frame wins)\n", r.droppedFrames);
  if (r.latency.count)
    std::printf("latency        median %.1f ms, p95 %.1f ms (capture to pose, %zu tracked frames)\n", r.latency.medianMs,
                r.latency.p95Ms, r.latency.count);
  if (r.resizedWidth)
    std::printf("resized        %dx%d -> %dx%d\n", r.inputWidth, r.inputHeight, r.resizedWidth, r.resizedHeight);
  if (r.interrupted) std::printf("interrupted    by a signal: outputs hold what was computed until then\n");
  if (r.ateRmse)
    std::printf("ATE (%s)     %.4f m RMSE over %zu poses (path %.2f m, %.2f%%)\n", r.ateAlignment == "sim3" ? "Sim3" : "SE3 ",
                *r.ateRmse, r.ateMatched, r.pathLength, r.pathLength > 0 ? 100 * *r.ateRmse / r.pathLength : 0.0);
  if (r.ateKeyFramesRmse)
    std::printf("  keyframes    %.4f m RMSE over %zu keyframes\n", *r.ateKeyFramesRmse, r.ateKeyFramesMatched);
  std::printf("\n%-32s %7s %9s %9s %9s\n", "stage", "count", "mean ms", "median", "p95");
  for (const StageStats& s : r.timing)
    std::printf("%-32s %7zu %9.2f %9.2f %9.2f\n", s.stage.c_str(), s.count, s.meanMs, s.medianMs, s.p95Ms);
  for (const auto& w : readableWarnings(foldWarnings(r.warnings))) std::fprintf(stderr, "warning: %s\n", w.c_str());
  std::printf("\noutputs in %s (trajectory.txt, trajectory_maps.txt, keyframes.txt, report.json, map.ply, overview.png)\n",
              options.outDir.string().c_str());
}

ORBIS_REGISTER_COMMAND("run", "SLAM on a dataset (TUM RGB-D, EuRoC, KITTI odometry and raw), a video, an image folder or a camera", runCommand);

}  // namespace
}  // namespace orbis::cli
