// `orbis calibrate images|video|camera PATH --pattern SPEC --out FILE.yaml [--right PATH2 |
// --stereo PACKING]`: camera (or stereo rig) calibration from views of a chessboard or ChArUco
// board (orbis/calibration/calibrate.hpp and stereo_calibrate.hpp do the work).
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
#include "orbis/calibration/stereo_calibrate.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/progress.hpp"

namespace orbis::cli {
namespace {

namespace fs = std::filesystem;
using namespace orbis::calibration;

// The frames of a source as calibration views, and the image of each view that shows the pattern
// (for the report's preview). Images: a folder, read directly by the calibration library; video
// files and live cameras through the streaming frame sources, one frame every `step` seconds
// (a camera for at most `seconds`). A stereo rig (`right`: a second folder, video or camera, or
// `packing`: both images in each frame) fills `right` and `rightImages` too, pair i being
// views[i] and right[i].
struct CollectedViews {
  std::vector<CalibrationView> views, right;
  std::map<std::string, cv::Mat> images, rightImages;
};

// How the frames come: the source kind and path, the rig's second source or packing, the pace.
struct Collection {
  std::string kind, path;
  std::optional<std::string> right;
  StereoPacking packing = StereoPacking::None;
  double step = 0.5, seconds = 60;
  bool progress = true;
  bool stereo() const { return right.has_value() || packing != StereoPacking::None; }
};

std::vector<CalibrationView> detectFolder(const std::string& path, const CalibrationPattern& pattern, bool progress) {
  std::optional<ProgressBar> bar;
  std::vector<CalibrationView> views = detectInFolder(path, pattern, [&](std::size_t done, std::size_t total) {
    if (!bar) bar.emplace("calibrate: detecting in " + path, total, progress);
    bar->update(done);
  });
  if (bar) bar->finish();
  return views;
}

std::unique_ptr<FrameSource> openSource(const Collection& c) {
  if (c.kind != "images" && c.kind != "video" && c.kind != "camera")
    throw Error("argument SOURCE", "", "expected images, video or camera, not '" + c.kind + "'");
  SourceOptions options;
  options.grey = true;
  options.stereo = c.packing;
  const auto open = [&](const std::string& path) -> std::unique_ptr<FrameSource> {
    if (c.kind == "video") return openVideoSource(path, options);
    if (c.kind == "images") return openImageFolderSource(path, options);
    return openCameraSource(path, options);
  };
  if (c.right) return makeStereoPairSource(open(c.path), open(*c.right));
  return open(c.path);
}

CollectedViews collectViews(const Collection& c, const CalibrationPattern& pattern) {
  CollectedViews out;
  if (c.kind == "images" && !c.stereo()) {
    out.views = detectFolder(c.path, pattern, c.progress);
    return out;
  }
  if (c.kind == "images" && c.right) {
    out.views = detectFolder(c.path, pattern, c.progress);
    out.right = detectFolder(*c.right, pattern, c.progress);
    return out;
  }
  const std::unique_ptr<FrameSource> source = openSource(c);
  const double step = c.kind == "images" ? 0.0 : c.step;
  ProgressBar bar("calibrate: " + source->name(), source->expectedFrames().value_or(0), c.progress);
  double last = -std::numeric_limits<double>::infinity(), first = std::numeric_limits<double>::quiet_NaN();
  std::size_t read = 0;
  while (const std::optional<SourceFrame> frame = source->next()) {
    ++read;
    bar.update(read);
    if (std::isnan(first)) first = frame->timestamp;
    if (c.kind == "camera" && frame->timestamp - first > c.seconds) break;
    if (frame->timestamp - last < step) continue;
    last = frame->timestamp;
    const std::string name = "frame_" + std::to_string(frame->index);
    CalibrationView view = detectView(frame->image, name, pattern);
    if (view.detection) out.images[name] = frame->image;
    out.views.push_back(std::move(view));
    if (c.stereo()) {
      CalibrationView right = detectView(frame->right, name + "_right", pattern);
      if (right.detection) out.rightImages[right.name] = frame->right;
      out.right.push_back(std::move(right));
    }
  }
  bar.finish();
  if (out.views.empty())
    throw Error(source->name(), "", "delivered no frame" + (source->endReason().empty() ? std::string() : ": " + source->endReason()));
  // Two streams of different lengths: their frames do not pair up.
  if (c.right && source->endReason().find("ended before") != std::string::npos)
    throw Error(source->name(), "", source->endReason() + ": a stereo rig is calibrated from pairs taken at the same "
                                    "moment; give two recordings of the same length, frame i of each taken together");
  return out;
}

// The image of a used view, for the report's preview.
cv::Mat previewImage(const Collection& c, const CollectedViews& collected, const std::string& name, bool right) {
  if (c.kind == "images" && (!c.stereo() || c.right))
    return cv::imread((std::filesystem::path(right ? *c.right : c.path) / name).string(), cv::IMREAD_UNCHANGED);
  const auto& images = right ? collected.rightImages : collected.images;
  const auto it = images.find(name);
  return it == images.end() ? cv::Mat() : it->second;
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

void printStereoSummary(const StereoCalibrationResult& r, const fs::path& out, const std::optional<fs::path>& report) {
  std::printf("calibrate: stereo rig, %s model, %d of %zu pairs for the extrinsics\n", toString(r.left.camera.model),
              r.pairsUsed, r.pairs.size());
  for (const auto& [side, camera] : {std::pair<const char*, const CalibrationResult*>{"left", &r.left}, {"right", &r.right}}) {
    std::printf("  %s camera: %d views, RMS %.3f px\n", side, camera->viewsUsed, camera->rms);
    for (std::size_t k = 0; k < camera->parameterNames.size(); ++k)
      std::printf("    %-3s %14.6f  +- %.6f\n", camera->parameterNames[k].c_str(), camera->parameters[k],
                  camera->standardDeviations[k]);
  }
  const Eigen::Vector3d t = r.rightFromLeft.translation();
  std::printf("  baseline       %.6f m +- %.6f (t = %.5f %.5f %.5f), stereo RMS %.3f px\n", r.baseline, r.baselineSigma,
              t.x(), t.y(), t.z(), r.rms);
  const PinholeCamera<double>& k = r.rectification.camera.pinhole;
  std::printf("  rectified      fx %.3f fy %.3f cx %.3f cy %.3f, bf %.4f\n", k.fx, k.fy, k.cx, k.cy,
              k.fx * r.rectification.camera.baseline);
  for (const StereoPairOutcome& p : r.pairs)
    if (!p.used) std::printf("  pair not used: %-24s %s\n", p.name.c_str(), p.rejected.c_str());
  for (const std::string& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
  std::printf("  settings       %s\n", out.string().c_str());
  if (report)
    std::printf("  report         %s (report.json, rectified.png, left/ and right/)\n", report->string().c_str());
}

int runCalibrate(const std::vector<std::string>& args) {
  ArgParser p("orbis calibrate images|video|camera PATH --pattern SPEC --out FILE.yaml [options]",
              "Calibrates a camera from views of a chessboard or ChArUco board: detects the corners (subpixel),\n"
              "drops blurred and duplicate views, keeps a well-spread set, fits a pinhole with radial-tangential\n"
              "distortion or a Kannala-Brandt fisheye, and writes the settings YAML `orbis run --settings` takes.\n"
              "A stereo rig (--right, or --stereo for frames holding both images) gets both cameras, the extrinsics\n"
              "and the rectification, written as rectified stereo settings.");
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
      .option("--right", "PATH", "a stereo rig: the right camera's folder, video or device (PATH is the left's)")
      .option("--stereo", "side-by-side|top-bottom", "a stereo rig whose frames hold both images (left first)")
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

  Collection collection;
  collection.kind = p.pos(0);
  collection.path = p.pos(1);
  collection.step = p.getDouble("--step");
  collection.seconds = p.getDouble("--seconds");
  collection.progress = !json;
  if (!(collection.step >= 0)) throw Error("argument --step", "", "must not be negative");
  if (!(collection.seconds > 0)) throw Error("argument --seconds", "", "must be positive");
  if (auto right = p.getOptional("--right")) collection.right = *right;
  if (auto packing = p.getOptional("--stereo")) {
    collection.packing = parseStereoPacking(*packing, "argument --stereo");
    if (collection.right) throw Error("argument --stereo", "", "cannot be combined with --right");
  }
  const fs::path source = p.pos(1);
  const CollectedViews collected = collectViews(collection, pattern);
  if (collection.stereo()) {
    const std::string name = collection.right ? source.string() + " + " + *collection.right : source.string();
    const StereoCalibrationResult result = calibrateStereo(collected.views, collected.right, pattern, options, name);
    writeStereoCalibrationSettings(out, result, fps);
    if (report) {
      cv::Mat left, right;
      for (std::size_t i = 0; i < result.pairs.size() && left.empty(); ++i)
        if (result.pairs[i].used) {
          left = previewImage(collection, collected, collected.views[i].name, false);
          right = previewImage(collection, collected, collected.right[i].name, true);
        }
      writeStereoCalibrationReport(*report, result, pattern, left, right);
    }
    if (json) std::printf("%s\n", stereoCalibrationJson(result, pattern, out).c_str());
    else printStereoSummary(result, out, report);
    return 0;
  }
  const CalibrationResult result = calibrate(collected.views, pattern, options, source.string());
  writeCalibrationSettings(out, result.camera, fps);
  if (report) {
    cv::Mat preview;
    if (!result.usedNames.empty()) preview = previewImage(collection, collected, result.usedNames.front(), false);
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
