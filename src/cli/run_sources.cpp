#include "run_sources.hpp"

#include <csignal>

#include "orbis/util/error.hpp"

namespace orbis::cli {

namespace {

volatile std::sig_atomic_t interruptSignal = 0;

extern "C" void onRunInterrupt(int signal) {
  interruptSignal = signal;
  std::signal(signal, SIG_DFL);  // a second Ctrl-C ends the program at once
}

SourceOptions sourceOptions(const ArgParser& p) {
  SourceOptions o;
  if (p.has("--fps")) {
    o.fps = p.getDouble("--fps");
    if (!(o.fps > 0)) throw Error("argument --fps", "", "must be positive");
  }
  if (auto t = p.getOptional("--times")) o.timesFile = *t;
  if (auto s = p.getOptional("--stereo")) o.stereo = parseStereoPacking(*s, "argument --stereo");
  if (p.has("--stall")) {
    o.stallSeconds = p.getDouble("--stall");
    if (!(o.stallSeconds > 0)) throw Error("argument --stall", "", "must be positive");
  }
  return o;
}

std::unique_ptr<FrameSource> openOne(const std::string& kind, const std::string& path, const SourceOptions& o) {
  if (kind == "video") return openVideoSource(path, o);
  if (kind == "images") return openImageFolderSource(path, o);
  return openCameraSource(path, o);
}

}  // namespace

bool isStreamSourceKind(const std::string& kind) { return kind == "video" || kind == "images" || kind == "camera"; }

std::unique_ptr<FrameSource> openStreamSource(const std::string& kind, const ArgParser& p) {
  const bool hasPath = p.positionalCount() > 1;
  if (!hasPath && kind != "camera")
    throw Error("arguments", "", std::string("missing PATH: the ") + (kind == "video" ? "video file or URL" : "image folder"));
  const std::string path = hasPath ? p.pos(1) : "0";
  const SourceOptions options = sourceOptions(p);
  // A plain flag and value rather than an optional: GCC 12 warns (wrongly) of an uninitialised optional.
  const bool sensorGiven = p.has("--sensor");
  const SensorKind sensor = sensorGiven ? parseSensorKind(p.get("--sensor"), "argument --sensor") : SensorKind::Monocular;
  std::unique_ptr<FrameSource> source;
  if (auto depth = p.getOptional("--depth")) {
    if (kind != "images") throw Error("argument --depth", "", "pairs colour and depth image folders: use it with `orbis run images`");
    if (sensorGiven && sensor != SensorKind::Rgbd) throw Error("argument --depth", "", "needs --sensor rgbd (or no --sensor)");
    source = openRgbdFolderSource(path, *depth, options);
  } else if (auto right = p.getOptional("--right")) {
    if (options.stereo != StereoPacking::None) throw Error("argument --right", "", "cannot be combined with --stereo");
    if (sensorGiven && sensor != SensorKind::Stereo) throw Error("argument --right", "", "needs --sensor stereo (or no --sensor)");
    source = makeStereoPairSource(openOne(kind, path, options), openOne(kind, *right, options));
  } else {
    if (sensorGiven && sensor == SensorKind::Stereo && options.stereo == StereoPacking::None)
      throw Error("argument --sensor", "", "stereo from one source needs --stereo side-by-side|top-bottom, or a second source with --right");
    if (sensorGiven && sensor == SensorKind::Rgbd) throw Error("argument --sensor", "", "rgbd needs a depth folder: --depth DIR");
    source = openOne(kind, path, options);
  }
  // A recording played as a live camera: at its own pace, and what tracking is late for is dropped.
  if (p.has("--realtime")) source = makeLiveSource(std::move(source), true, options.stallSeconds);
  return source;
}

void catchInterrupts() {
  interruptSignal = 0;
  std::signal(SIGINT, onRunInterrupt);
  std::signal(SIGTERM, onRunInterrupt);
}

bool interruptRequested() { return interruptSignal != 0; }

}  // namespace orbis::cli
