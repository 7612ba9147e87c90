// `orbis calibrate images|video|camera PATH --pattern SPEC --out FILE.yaml`: camera calibration
// from views of a chessboard or ChArUco board (orbis/calibration/calibrate.hpp does the work).
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "command.hpp"
#include "orbis/adapters/frame_source.hpp"
#include "orbis/calibration/calibrate.hpp"
#include "orbis/calibration/calibration_output.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/progress.hpp"

namespace orbis::cli {
namespace {

namespace fs = std::filesystem;
using namespace orbis::calibration;

// The frames of a source as calibration views, and the image of each view that shows the pattern
// (for the report's preview). Images: a folder, read directly by the calibration library; video
// files and live cameras through the streaming frame sources, one frame every `step` seconds
// (a camera for at most `seconds`).
struct CollectedViews {
  std::vector<CalibrationView> views;
  std::map<std::string, cv::Mat> images;
};

CollectedViews collectViews(const std::string& kind, const std::string& path, const CalibrationPattern& pattern,
                            double step, double seconds, bool progress) {
  CollectedViews out;
  if (kind == "images") {
    std::optional<ProgressBar> bar;
    out.views = detectInFolder(path, pattern, [&](std::size_t done, std::size_t total) {
      if (!bar) bar.emplace("calibrate: detecting", total, progress);
      bar->update(done);
    });
    if (bar) bar->finish();
    return out;
  }
  if (kind != "video" && kind != "camera")
    throw Error("argument SOURCE", "", "expected images, video or camera, not '" + kind + "'");
  SourceOptions options;
  options.grey = true;
  const std::unique_ptr<FrameSource> source = kind == "video" ? openVideoSource(path, options) : openCameraSource(path, options);
  ProgressBar bar("calibrate: " + source->name(), source->expectedFrames().value_or(0), progress);
  double last = -std::numeric_limits<double>::infinity(), first = std::numeric_limits<double>::quiet_NaN();
  std::size_t read = 0;
  while (const std::optional<SourceFrame> frame = source->next()) {
    ++read;
    bar.update(read);
    if (std::isnan(first)) first = frame->timestamp;
    if (kind == "camera" && frame->timestamp - first > seconds) break;
    if (frame->timestamp - last < step) continue;
    last = frame->timestamp;
    const std::string name = "frame_" + std::to_string(frame->index);
    CalibrationView view = detectView(frame->image, name, pattern);
    if (view.detection) out.images[name] = frame->image;
    out.views.push_back(std::move(view));
  }
  bar.finish();
  if (out.views.empty())
    throw Error(source->name(), "", "delivered no frame" + (source->endReason().empty() ? std::string() : ": " + source->endReason()));
  return out;
}

void printSummary(const CalibrationResult& r, const fs::path& out, const std::optional<fs::path>& report) {
  const CalibratedCamera& c = r.camera;
  std::printf("calibrate: %s model from %d of %zu views, RMS %.3f px\n", toString(c.model), r.viewsUsed,
              r.views.size(), r.rms);
  for (std::size_t k = 0; k < r.parameterNames.size(); ++k)
    std::printf("  %-3s %14.6f  +- %.6f\n", r.parameterNames[k].c_str(), r.parameters[k], r.standardDeviations[k]);
  if (c.model == LensModel::Fisheye)
    std::printf("  field of view  %.1f degrees (widest angle off axis %.1f)\n", 2 * c.fieldOfViewAngle() * 180 / M_PI,
                c.fieldOfViewAngle() * 180 / M_PI);
  for (const ViewOutcome& v : r.views)
    if (!v.used) std::printf("  not used: %-28s %s\n", v.name.c_str(), v.rejected.c_str());
  for (const std::string& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
  std::printf("  settings       %s\n", out.string().c_str());
  if (report) std::printf("  report         %s (report.json, coverage.png, undistorted.png)\n", report->string().c_str());
}

int runCalibrate(const std::vector<std::string>& args) {
  ArgParser p("orbis calibrate images|video|camera PATH --pattern SPEC --out FILE.yaml [options]",
              "Calibrates a camera from views of a chessboard or ChArUco board: detects the corners (subpixel),\n"
              "drops blurred and duplicate views, keeps a well-spread set, fits a pinhole with radial-tangential\n"
              "distortion or a Kannala-Brandt fisheye, and writes the settings YAML `orbis run --settings` takes.");
  p.positional("SOURCE", "images (a folder of images), video (a video file) or camera (a device)")
      .positional("PATH", "the folder, file or device")
      .option("--pattern", "SPEC",
              "chessboard:COLSxROWS:SQUARE (inner corners, metres) or charuco:COLSxROWS:SQUARE:MARKER[:DICT] "
              "(squares, metres, aruco dictionary, default DICT_4X4_50)")
      .option("--model", "pinhole|fisheye", "lens model: pinhole (k1 k2 p1 p2 k3) or fisheye (Kannala-Brandt k1..k4)",
              "pinhole")
      .option("--out", "FILE.yaml", "the settings file to write")
      .option("--report", "DIR", "also write report.json, coverage.png and undistorted.png into DIR")
      .option("--min-views", "N", "fewest usable views to calibrate from", "6")
      .option("--max-views", "N", "most views fitted (a well-spread subset beyond)", "40")
      .option("--max-blur", "PX", "chessboard: views whose black-to-white edge rise is wider are blurred", "4")
      .option("--fps", "HZ", "Camera.fps written to the settings", "30")
      .option("--step", "S", "video and camera: use one frame every S seconds", "0.5")
      .option("--seconds", "S", "camera: calibrate from this many seconds of frames", "60")
      .flag("--json", "print the result as one JSON object");
  if (!p.parse(args)) return 0;
  if (!p.getOptional("--pattern")) throw Error("argument --pattern", "", "missing: say which board the images show, e.g. --pattern chessboard:9x6:0.025");
  if (!p.getOptional("--out")) throw Error("argument --out", "", "missing: the settings file to write, e.g. --out camera.yaml");
  const CalibrationPattern pattern = parsePattern(p.get("--pattern"));
  CalibrationOptions options;
  options.model = parseLensModel(p.get("--model"));
  options.minViews = static_cast<int>(p.getInt("--min-views"));
  options.maxViews = static_cast<int>(p.getInt("--max-views"));
  if (options.minViews < 3) throw Error("argument --min-views", "", "must be at least 3");
  if (options.maxViews < options.minViews) throw Error("argument --max-views", "", "must be at least --min-views");
  options.maxEdgeWidth = p.getDouble("--max-blur");
  const double fps = p.getDouble("--fps");
  if (!(fps > 0)) throw Error("argument --fps", "", "must be positive");
  const fs::path out = p.get("--out");
  const std::optional<fs::path> report = p.getOptional("--report") ? std::optional<fs::path>(p.get("--report")) : std::nullopt;
  const bool json = p.has("--json");

  const double step = p.getDouble("--step"), seconds = p.getDouble("--seconds");
  if (!(step >= 0)) throw Error("argument --step", "", "must not be negative");
  if (!(seconds > 0)) throw Error("argument --seconds", "", "must be positive");
  const fs::path source = p.pos(1);
  const CollectedViews collected = collectViews(p.pos(0), p.pos(1), pattern, step, seconds, !json);
  const CalibrationResult result = calibrate(collected.views, pattern, options, source.string());
  writeCalibrationSettings(out, result.camera, fps);
  if (report) {
    cv::Mat preview;
    if (!result.usedNames.empty()) {
      const std::string& first = result.usedNames.front();
      preview = p.pos(0) == "images" ? cv::imread((source / first).string(), cv::IMREAD_UNCHANGED)
                                     : collected.images.at(first);
    }
    writeCalibrationReport(*report, result, pattern, preview);
  }
  if (json) std::printf("%s\n", calibrationJson(result, pattern, out).c_str());
  else printSummary(result, out, report);
  return 0;
}

}  // namespace

ORBIS_REGISTER_COMMAND("calibrate", "calibrate a camera from chessboard or ChArUco views (writes settings YAML)",
                       runCalibrate);

}  // namespace orbis::cli
