// `orbis synth OUTDIR`: renders a synthetic room sequence with exact ground truth into one of
// the TUM RGB-D, EuRoC or KITTI layouts (see orbis/synth/writers.hpp).
#include <cmath>
#include <cstdio>
#include <algorithm>
#include <string>
#include <vector>

#include "command.hpp"
#include "orbis/calibration/pattern.hpp"
#include "orbis/synth/calibration_views.hpp"
#include "orbis/synth/writers.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"
#include "orbis/util/progress.hpp"

namespace orbis::cli {
namespace {

// "START:COUNT" → (start, count).
std::pair<int, int> parseSegment(const std::string& text, const std::string& argument) {
  const auto colon = text.find(':');
  std::size_t used1 = 0, used2 = 0;
  int start = -1, count = -1;
  try {
    if (colon != std::string::npos) {
      start = std::stoi(text.substr(0, colon), &used1);
      count = std::stoi(text.substr(colon + 1), &used2);
    }
  } catch (const std::exception&) {
    start = -1;
  }
  if (colon == std::string::npos || used1 != colon || used2 != text.size() - colon - 1 || start < 0 || count < 0)
    throw Error("argument " + argument, "", "expected START:COUNT (two non-negative integers), got '" + text + "'");
  return {start, count};
}

// "a,b,c,..." → the lens's coefficients: fisheye k1..k4, pinhole k1 k2 p1 p2 [k3].
std::vector<double> parseDistortion(const std::string& text, bool fisheye) {
  std::vector<double> values;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v))
      throw Error("argument --distortion", "", "expected comma-separated numbers, not '" + text + "'");
    values.push_back(v);
    start = end + 1;
  }
  if (fisheye ? values.size() != 4 : values.size() != 4 && values.size() != 5)
    throw Error("argument --distortion", "", fisheye ? "a fisheye takes four coefficients k1,k2,k3,k4"
                                                     : "a pinhole takes k1,k2,p1,p2 or k1,k2,p1,p2,k3");
  if (!fisheye && values.size() == 4) values.push_back(0.0);
  return values;
}

// `--pattern`: views of a calibration board through the requested lens, with the truth.
int renderCalibrationTarget(const ArgParser& p, const synth::SynthOptions& o, const std::vector<double>& distortion,
                            const std::string& patternText) {
  synth::CalibrationViewsOptions v;
  v.pattern = calibration::parsePattern(patternText);
  v.views = static_cast<int>(p.getInt("--views"));
  if (v.views <= 0 || v.views > 10000) throw Error("argument --views", "", "expected a positive number of views");
  v.seed = o.seed;
  v.noiseSigma = o.noiseSigma;
  v.supersample = std::max(o.supersample, 3);
  calibration::CalibratedCamera& c = v.camera;
  c.width = o.width;
  c.height = o.height;
  if (o.fisheye) {
    const synth::SyntheticSequence lens(o);  // its fisheye camera: fx from --fov
    const KannalaBrandtCamera<double> k = lens.fisheyeCamera();
    c.model = calibration::LensModel::Fisheye;
    c.fx = k.fx, c.fy = k.fy, c.cx = k.cx, c.cy = k.cy;
    c.distortion = {k.k1, k.k2, k.k3, k.k4};
  } else {
    c.fx = o.fx;
    c.fy = p.getOptional("--fy") ? p.getDouble("--fy") : o.fx;
    c.cx = p.getOptional("--cx") ? p.getDouble("--cx") : 0.5 * o.width;
    c.cy = p.getOptional("--cy") ? p.getDouble("--cy") : 0.5 * o.height;
    if (!(c.fx > 0 && c.fy > 0)) throw Error("argument --fx", "", "focal lengths must be positive");
    c.distortion = distortion.empty() ? std::vector<double>(5, 0.0) : distortion;
  }
  const bool json = p.has("--json");
  v.squareOn = p.has("--square-on");
  if (p.has("--rig")) {
    // The right camera: the same lens, --baseline to the right, the optical axes parallel.
    if (!(o.baseline > 0)) throw Error("argument --baseline", "", "a stereo rig needs a positive baseline");
    v.rightCamera = c;
    v.rightFromLeft = SE3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-o.baseline, 0, 0));
  }
  const std::vector<synth::RenderedCalibrationView> views = synth::renderCalibrationViews(v);
  const std::filesystem::path images = v.rightCamera ? synth::writeStereoCalibrationViews(p.pos(0), views, v)
                                                     : synth::writeCalibrationViews(p.pos(0), views, c);
  if (json) {
    JsonWriter w;
    w.beginObject().field("images", images.string()).field("truth", (std::filesystem::path(p.pos(0)) / "truth.yaml").string())
        .field("views", views.size()).field("model", calibration::toString(c.model)).field("fx", c.fx).field("fy", c.fy)
        .field("cx", c.cx).field("cy", c.cy);
    w.key("distortion").beginArray();
    for (double d : c.distortion) w.value(d);
    w.endArray().endObject();
    std::printf("%s\n", w.str().c_str());
  } else {
    std::printf("synth: %zu views of %s through a %s lens (fx %.3f, %dx%d)\n  images %s\n  truth  %s\n", views.size(),
                v.pattern.describe().c_str(), calibration::toString(c.model), c.fx, c.width, c.height,
                images.string().c_str(), (std::filesystem::path(p.pos(0)) / "truth.yaml").string().c_str());
  }
  return 0;
}

int runSynth(const std::vector<std::string>& args) {
  ArgParser p("orbis synth OUTDIR [options]",
              "Renders a textured room along a closed-loop 6-DoF path into a dataset layout with exact\n"
              "ground truth, an ORB-SLAM2 settings.yaml and settings_mono.yaml.");
  p.positional("OUTDIR", "output directory (created; existing files are overwritten)")
      .option("--layout", "tum|euroc|kitti", "dataset layout: tum = RGB-D, euroc and kitti = stereo", "tum")
      .option("--frames", "N", "number of frames (one loop)", "300")
      .option("--extra", "N", "frames rendered past the loop's end over known ground (loop closing needs them)", "0")
      .option("--width", "W", "image width in pixels", "640")
      .option("--height", "H", "image height in pixels", "480")
      .option("--fx", "F", "focal length in pixels (fy = fx; pinhole only)", "500")
      .option("--camera", "pinhole|fisheye",
              "lens: an ideal pinhole, or a Kannala-Brandt fisheye (settings get Camera.type: KannalaBrandt8; the "
              "euroc layout's sensor.yaml says distortion_model: equidistant and is rectified on load)",
              "pinhole")
      .option("--fov", "DEG", "fisheye: field of view across the image width through its centre, degrees", "180")
      .option("--baseline", "B", "stereo baseline in metres (also the RGB-D virtual baseline)", "0.1")
      .option("--fps", "HZ", "frame rate", "30")
      .option("--noise", "SIGMA", "Gaussian image noise, grey levels", "0")
      .option("--depth-noise", "SIGMA", "Gaussian noise of the depth's inverse, 1/m (Kinect-like: 0.0014)", "0")
      .option("--blur", "N", "motion blur: sub-frames averaged per frame (1 = none)", "1")
      .option("--black", "START:COUNT", "black out COUNT frames from frame START (relocalisation tests)")
      .option("--flat", "START:COUNT", "textureless frames (uniform grey plus noise) from frame START")
      .option("--scene", "room|corridor",
              "room: the 11 m loop in a room looking outwards; corridor: a 27 m loop round a central block "
              "looking ahead (the start leaves the view for most of the loop)",
              "room")
      .option("--motion", "loop|rotation|static", "camera motion: the loop, a pure rotation in place, or none", "loop")
      .option("--seed", "S", "seed of the scene, textures and noise", "1")
      .option("--pattern", "SPEC",
              "render calibration views of this board instead of a sequence (chessboard:COLSxROWS:SQUARE or "
              "charuco:COLSxROWS:SQUARE:MARKER[:DICT], as orbis calibrate): OUTDIR/images, truth.yaml, poses.txt")
      .option("--views", "N", "calibration views to render (with --pattern)", "30")
      .flag("--square-on", "with --pattern, every board parallel to the image plane (a degenerate set calibration refuses)")
      .flag("--rig", "with --pattern, a stereo rig's views: a second camera with the same lens --baseline to the "
                     "right (OUTDIR/left, OUTDIR/right, truth.yaml the rig's rectified stereo settings)")
      .option("--fy", "F", "with --pattern, a pinhole's vertical focal length (default: --fx)")
      .option("--cx", "U", "with --pattern, the principal point's column (default: the image centre)")
      .option("--cy", "V", "with --pattern, the principal point's row (default: the image centre)")
      .option("--distortion", "LIST",
              "the lens's coefficients, comma-separated: pinhole k1,k2,p1,p2[,k3] (calibration views only); "
              "fisheye k1,k2,k3,k4 (default 0.01,-0.002,0.0005,0)")
      .option("--supersample", "N", "rays per pixel along each axis (antialiasing)", "2")
      .option("--threads", "N", "rendering threads", "1")
      .flag("--json", "print the summary as one JSON object");
  if (!p.parse(args)) return 0;

  synth::SynthOptions o;
  const auto positiveInt = [&](const std::string& name) {
    const long v = p.getInt(name);
    if (v <= 0 || v > 1000000) throw Error("argument " + name, "", "expected a positive integer");
    return static_cast<int>(v);
  };
  o.frames = positiveInt("--frames");
  if (p.getInt("--extra") < 0) throw Error("argument --extra", "", "must be 0 or positive");
  o.extraFrames = static_cast<int>(p.getInt("--extra"));
  // A smaller render holds no ORB keypoint at all (each needs a 19-pixel border and a 31-pixel
  // patch), so SLAM on it could only fail later with a vaguer message.
  const auto imageSide = [&](const std::string& name) {
    const int v = positiveInt(name);
    if (v < 64) throw Error("argument " + name, "", "expected at least 64 pixels: ORB finds no keypoint in a smaller image");
    return v;
  };
  o.width = imageSide("--width");
  o.height = imageSide("--height");
  o.fx = p.getDouble("--fx");
  const std::string cameraName = p.get("--camera");
  if (cameraName != "pinhole" && cameraName != "fisheye")
    throw Error("argument --camera", "", "expected pinhole or fisheye, not '" + cameraName + "'");
  o.fisheye = cameraName == "fisheye";
  o.fisheyeFovDegrees = p.getDouble("--fov");
  std::vector<double> distortionList;
  o.baseline = p.getDouble("--baseline");
  o.fps = p.getDouble("--fps");
  o.noiseSigma = p.getDouble("--noise");
  o.depthNoise = p.getDouble("--depth-noise");
  o.blurSubframes = positiveInt("--blur");
  o.supersample = positiveInt("--supersample");
  o.threads = positiveInt("--threads");
  const long seed = p.getInt("--seed");
  if (seed < 0) throw Error("argument --seed", "", "expected a non-negative integer");
  o.seed = static_cast<std::uint64_t>(seed);
  if (auto black = p.getOptional("--black")) std::tie(o.blackStart, o.blackCount) = parseSegment(*black, "--black");
  if (auto flat = p.getOptional("--flat")) std::tie(o.flatStart, o.flatCount) = parseSegment(*flat, "--flat");
  const std::string motion = p.get("--motion");
  if (motion == "rotation") o.path.motion = synth::PathMotion::PureRotation;
  else if (motion == "static") o.path.motion = synth::PathMotion::Static;
  else if (motion != "loop") throw Error("argument --motion", "", "expected loop, rotation or static, not '" + motion + "'");
  if (auto distortion = p.getOptional("--distortion")) {
    distortionList = parseDistortion(*distortion, o.fisheye);
    if (o.fisheye) std::copy(distortionList.begin(), distortionList.end(), o.fisheyeK.begin());
  }
  if (auto pattern = p.getOptional("--pattern")) return renderCalibrationTarget(p, o, distortionList, *pattern);
  if (!o.fisheye && !distortionList.empty())
    throw Error("argument --distortion", "", "a pinhole sequence is rendered undistorted: give --distortion with "
                                             "--camera fisheye or with --pattern");
  const std::string scene = p.get("--scene");
  if (scene == "corridor") synth::applyScenePreset(synth::ScenePreset::Corridor, o.room, o.path);
  else if (scene != "room") throw Error("argument --scene", "", "expected room or corridor, not '" + scene + "'");
  const synth::SynthLayout layout = synth::parseSynthLayout(p.get("--layout"), "argument --layout");
  const bool json = p.has("--json");

  synth::SyntheticSequence sequence(o);
  ProgressBar bar("synth", static_cast<std::size_t>(o.frames + o.extraFrames), !json);
  const synth::SynthWriteResult r =
      synth::writeSynthSequence(sequence, layout, p.pos(0), [&](int done) { bar.update(static_cast<std::size_t>(done)); });
  bar.finish();
  // How far the last frame is from the first: the loop closes one frame-step before its start.
  const SE3d gap = sequence.pose(o.frames - 1).inverse() * sequence.pose(0);
  const double gapMetres = gap.translation().norm();
  const double gapDegrees = gap.so3().log().norm() * 180.0 / M_PI;
  // CPU time, not wall time: on a shared machine the wall clock measures the neighbours.
  const double cpuMsPerFrame = 1000.0 * r.renderCpuSeconds / r.frames;

  if (json) {
    JsonWriter w;
    w.beginObject()
        .field("layout", toString(layout))
        .field("root", r.root.string())
        .field("frames", r.frames)
        .field("black_frames", r.blackFrames)
        .field("width", o.width)
        .field("height", o.height)
        .field("camera", cameraName)
        .field("fx", sequence.camera().fx)
        .field("fov_deg", o.fisheye ? o.fisheyeFovDegrees : 2 * std::atan(0.5 * o.width / o.fx) * 180 / M_PI)
        .field("baseline", o.baseline)
        .field("seed", static_cast<std::int64_t>(o.seed))
        .field("scene", scene)
        .field("rects", sequence.scene().rects().size())
        .field("ground_truth", r.groundTruth.string())
        .field("settings", r.settings.string())
        .field("settings_mono", r.settingsMono.string())
        .field("render_seconds", r.renderSeconds)
        .field("render_cpu_seconds", r.renderCpuSeconds)
        .field("cpu_ms_per_frame", cpuMsPerFrame)
        .field("total_seconds", r.totalSeconds)
        .field("loop_gap_m", gapMetres)
        .field("loop_gap_deg", gapDegrees)
        .endObject();
    std::printf("%s\n", w.str().c_str());
    return 0;
  }
  std::printf("synth: %d frames (%d black) of %dx%d, layout %s, seed %llu, %zu scene rectangles\n", r.frames,
              r.blackFrames, o.width, o.height, std::string(toString(layout)).c_str(),
              static_cast<unsigned long long>(o.seed), sequence.scene().rects().size());
  std::printf("  written to     %s\n  ground truth   %s\n  settings       %s (mono: %s)\n", r.root.string().c_str(),
              r.groundTruth.string().c_str(), r.settings.string().c_str(), r.settingsMono.filename().string().c_str());
  std::printf("  rendering      %.2f s CPU (%.1f ms CPU per frame), %.2f s wall on %d thread%s; total %.2f s\n",
              r.renderCpuSeconds, cpuMsPerFrame, r.renderSeconds, o.threads, o.threads == 1 ? "" : "s",
              r.totalSeconds);
  std::printf("  loop           last frame is %.3f m / %.2f deg from the first\n", gapMetres, gapDegrees);
  return 0;
}

}  // namespace

ORBIS_REGISTER_COMMAND("synth", "render a synthetic closed-loop sequence (TUM, EuRoC or KITTI layout)", runSynth);

}  // namespace orbis::cli
