// ORB-SLAM2 settings reader; see orbis/io/settings.hpp.
#include "orbis/io/settings.hpp"

#include <array>
#include <cmath>
#include <iterator>

#include "../camera/yaml_reader.hpp"

namespace orbis {

namespace {

using detail::YamlReader;

constexpr SettingsKey kSettingsKeys[] = {
    {"Sensor", "text", "mono, stereo or rgbd (orbis; default: inferred from Camera.bf and DepthMapFactor)"},
    {"Camera.fx", "number", "focal length in x, pixels"},
    {"Camera.fy", "number", "focal length in y, pixels"},
    {"Camera.cx", "number", "principal point x, pixels"},
    {"Camera.cy", "number", "principal point y, pixels"},
    {"Camera.k1", "number", "radial distortion k1 of the input images"},
    {"Camera.k2", "number", "radial distortion k2"},
    {"Camera.p1", "number", "tangential distortion p1"},
    {"Camera.p2", "number", "tangential distortion p2"},
    {"Camera.k3", "number", "radial distortion k3 (optional, default 0)"},
    {"Camera.width", "whole number", "image width (optional: taken from the first image)"},
    {"Camera.height", "whole number", "image height (optional: taken from the first image)"},
    {"Camera.fps", "number", "frame rate (optional, 0 or absent: 30)"},
    {"Camera.newWidth", "whole number", "scale images and intrinsics to this width before extraction (ORB-SLAM3; --resize wins)"},
    {"Camera.bf", "number", "stereo baseline times fx (stereo and rgbd)"},
    {"Camera.RGB", "whole number", "1: colour images are RGB, 0: BGR"},
    {"Camera.type", "text", "lens model: PinHole (default) or KannalaBrandt8 (fisheye, ORB-SLAM3)"},
    {"Camera.k4", "number", "KannalaBrandt8: fisheye coefficient k4 (k1..k3 as Camera.k1..k3)"},
    {"Camera.maxAngle", "number", "KannalaBrandt8: widest angle off axis the lens is trusted at, degrees (orbis, default 180)"},
    {"Camera1.fx", "number", "ORB-SLAM3 layout (KannalaBrandt8): focal length in x, pixels"},
    {"Camera1.fy", "number", "ORB-SLAM3 layout: focal length in y, pixels"},
    {"Camera1.cx", "number", "ORB-SLAM3 layout: principal point x, pixels"},
    {"Camera1.cy", "number", "ORB-SLAM3 layout: principal point y, pixels"},
    {"Camera1.k1", "number", "ORB-SLAM3 layout: fisheye coefficient k1"},
    {"Camera1.k2", "number", "ORB-SLAM3 layout: fisheye coefficient k2"},
    {"Camera1.k3", "number", "ORB-SLAM3 layout: fisheye coefficient k3"},
    {"Camera1.k4", "number", "ORB-SLAM3 layout: fisheye coefficient k4"},
    {"System.seed", "whole number", "seed of every random choice of the system (orbis, default 0)"},
    {"ThDepth", "number", "close/far depth threshold, in baselines (default 40)"},
    {"DepthMapFactor", "number", "raw depth / factor = metres (rgbd)"},
    {"DepthDisparitySigma", "number", "sigma of the depth sensor's virtual disparity, pixels (orbis, rgbd)"},
    {"ORBextractor.nFeatures", "whole number", "features per image (the feature budget)"},
    {"ORBextractor.scaleFactor", "number", "scale between pyramid levels (> 1)"},
    {"ORBextractor.nLevels", "whole number", "pyramid levels"},
    {"ORBextractor.iniThFAST", "whole number", "FAST threshold tried first"},
    {"ORBextractor.minThFAST", "whole number", "FAST threshold where the first finds too few corners"},
    {"ORBextractor.rightFeaturesFactor", "whole number", "right image's budget multiple (stereo, orbis)"},
    {"LEFT.K", "matrix", "left camera: 3x3 intrinsics before rectification"},
    {"LEFT.D", "matrix", "left camera: distortion k1 k2 p1 p2 [k3] (KannalaBrandt8: k1 k2 k3 k4)"},
    {"LEFT.type", "text", "left camera: KannalaBrandt8 for a fisheye (D holds k1..k4); default pinhole"},
    {"LEFT.R", "matrix", "left camera: 3x3 rectifying rotation"},
    {"LEFT.P", "matrix", "left camera: 3x4 projection after rectification"},
    {"LEFT.width", "whole number", "left camera: image width"},
    {"LEFT.height", "whole number", "left camera: image height"},
    {"RIGHT.K", "matrix", "right camera: 3x3 intrinsics before rectification"},
    {"RIGHT.D", "matrix", "right camera: distortion k1 k2 p1 p2 [k3] (KannalaBrandt8: k1 k2 k3 k4)"},
    {"RIGHT.type", "text", "right camera: KannalaBrandt8 for a fisheye (D holds k1..k4); default pinhole"},
    {"RIGHT.R", "matrix", "right camera: 3x3 rectifying rotation"},
    {"RIGHT.P", "matrix", "right camera: 3x4 projection after rectification"},
    {"RIGHT.width", "whole number", "right camera: image width"},
    {"RIGHT.height", "whole number", "right camera: image height"},
};

// The names alone, for YamlReader::acceptOnly.
std::span<const std::string_view> settingsKeyNames() {
  static const auto names = [] {
    std::array<std::string_view, std::size(kSettingsKeys)> n{};
    for (std::size_t i = 0; i < n.size(); ++i) n[i] = kSettingsKeys[i].name;
    return n;
  }();
  return names;
}

SensorKind chooseSensor(const YamlReader& yaml, std::optional<SensorKind> requested) {
  if (requested) return *requested;
  if (const auto name = yaml.optionalString("Sensor")) {
    return parseSensorKind(*name, yaml.path(), "key Sensor");
  }
  if (!yaml.has("Camera.bf")) return SensorKind::Monocular;
  return yaml.has("DepthMapFactor") ? SensorKind::Rgbd : SensorKind::Stereo;
}

double positive(const YamlReader& yaml, const std::string& key) {
  const double value = yaml.real(key);
  if (!(value > 0)) throw yaml.error(key, "must be positive, found " + std::to_string(value));
  return value;
}

int positiveInteger(const YamlReader& yaml, const std::string& key) {
  const int value = yaml.integer(key);
  if (value <= 0) throw yaml.error(key, "must be a positive whole number, found " + std::to_string(value));
  return value;
}

PinholeCamera<double> readPinhole(const YamlReader& yaml) {
  PinholeCamera<double> camera;
  camera.fx = positive(yaml, "Camera.fx");
  camera.fy = positive(yaml, "Camera.fy");
  camera.cx = yaml.real("Camera.cx");
  camera.cy = yaml.real("Camera.cy");
  // Optional in ORB-SLAM2's files; 0 = taken from the first image.
  if (yaml.has("Camera.width")) camera.width = positiveInteger(yaml, "Camera.width");
  if (yaml.has("Camera.height")) camera.height = positiveInteger(yaml, "Camera.height");
  return camera;
}

// Camera.type: KannalaBrandt8, with ORB-SLAM3's keys under Camera1. (File.version 1.0) or Camera.
KannalaBrandtCamera<double> readKannalaBrandt(const YamlReader& yaml) {
  const std::string prefix = yaml.has("Camera1.fx") ? "Camera1." : "Camera.";
  KannalaBrandtCamera<double> camera;
  camera.fx = positive(yaml, prefix + "fx");
  camera.fy = positive(yaml, prefix + "fy");
  camera.cx = yaml.real(prefix + "cx");
  camera.cy = yaml.real(prefix + "cy");
  camera.k1 = yaml.real(prefix + "k1");
  camera.k2 = yaml.real(prefix + "k2");
  camera.k3 = yaml.real(prefix + "k3");
  camera.k4 = yaml.real(prefix + "k4");
  if (yaml.has("Camera.width")) camera.width = positiveInteger(yaml, "Camera.width");
  if (yaml.has("Camera.height")) camera.height = positiveInteger(yaml, "Camera.height");
  if (const auto maxAngle = yaml.optionalReal("Camera.maxAngle")) {
    if (!(*maxAngle > 0 && *maxAngle <= 180)) throw yaml.error("Camera.maxAngle", "expected degrees in (0, 180]");
    camera.maxAngle = *maxAngle * M_PI / 180.0;
  }
  // The polynomial must increase over the angles it is used at, or pixels have two rays.
  for (double theta = 0.01; theta <= camera.maxAngle; theta += 0.01) {
    if (camera.distortAngleDerivative(theta) <= 0) {
      throw yaml.error(prefix + "k1",
                       "the fisheye polynomial k1..k4 stops increasing at " + std::to_string(theta * 180 / M_PI) +
                           " degrees off axis: set Camera.maxAngle below that, or check the coefficients");
    }
  }
  return camera;
}

bool isFisheye(const YamlReader& yaml) {
  const auto type = yaml.optionalString("Camera.type");
  if (!type || *type == "PinHole" || *type == "Pinhole" || *type == "pinhole") return false;
  if (*type == "KannalaBrandt8" || *type == "KannalaBrandt" || *type == "fisheye") return true;
  throw yaml.error("Camera.type", "expected PinHole or KannalaBrandt8, found \"" + *type + "\"");
}

RadTanDistortion<double> readDistortion(const YamlReader& yaml) {
  return {yaml.real("Camera.k1"), yaml.real("Camera.k2"), yaml.real("Camera.p1"), yaml.real("Camera.p2"),
          yaml.optionalReal("Camera.k3").value_or(0.0)};
}

OrbParams readOrbParams(const YamlReader& yaml) {
  OrbParams orb;
  orb.features = positiveInteger(yaml, "ORBextractor.nFeatures");
  orb.scaleFactor = static_cast<float>(yaml.real("ORBextractor.scaleFactor"));
  if (!(orb.scaleFactor > 1.0f)) throw yaml.error("ORBextractor.scaleFactor", "must be greater than 1");
  orb.levels = positiveInteger(yaml, "ORBextractor.nLevels");
  orb.iniThFast = positiveInteger(yaml, "ORBextractor.iniThFAST");
  orb.minThFast = positiveInteger(yaml, "ORBextractor.minThFAST");
  if (orb.iniThFast > 255) throw yaml.error("ORBextractor.iniThFAST", "must be at most 255");
  if (orb.minThFast > orb.iniThFast) throw yaml.error("ORBextractor.minThFAST", "must not exceed iniThFAST");
  if (yaml.has("ORBextractor.rightFeaturesFactor"))
    orb.rightFeaturesFactor = positiveInteger(yaml, "ORBextractor.rightFeaturesFactor");
  return orb;
}

RectificationBlock readBlock(const YamlReader& yaml, const std::string& prefix) {
  RectificationBlock block;
  block.K = yaml.matrix(prefix + "K", 3, 3);
  const Eigen::MatrixXd d = yaml.matrix(prefix + "D");
  if (yaml.has(prefix + "type")) {
    const std::string type = yaml.string(prefix + "type");
    if (type != "KannalaBrandt8" && type != "PinHole")
      throw yaml.error(prefix + "type", "expected KannalaBrandt8 (a fisheye) or PinHole, not '" + type + "'");
    if (type == "KannalaBrandt8") {
      if (std::min(d.rows(), d.cols()) != 1 || d.size() != 4)
        throw yaml.error(prefix + "D", "a KannalaBrandt8 camera takes 4 coefficients k1 k2 k3 k4 in one row");
      block.fisheye = std::array<double, 4>{d(0), d(1), d(2), d(3)};
    }
  }
  if (!block.fisheye) {
    if (std::min(d.rows(), d.cols()) != 1 || (d.size() != 4 && d.size() != 5))
      throw yaml.error(prefix + "D", "expected 4 or 5 distortion coefficients k1 k2 p1 p2 [k3] in one row");
    block.D = {d(0), d(1), d(2), d(3), d.size() == 5 ? d(4) : 0.0};
  }
  block.R = yaml.matrix(prefix + "R", 3, 3);
  block.P = yaml.matrix(prefix + "P", 3, 4);
  block.width = positiveInteger(yaml, prefix + "width");
  block.height = positiveInteger(yaml, prefix + "height");
  if (!(block.K(0, 0) > 0 && block.K(1, 1) > 0)) throw yaml.error(prefix + "K", "focal lengths must be positive");
  return block;
}

Settings loadSettings(const std::filesystem::path& file, std::optional<SensorKind> requested) {
  YamlReader yaml(file);
  yaml.acceptOnly(settingsKeyNames());
  Settings s;
  s.source = file;
  s.sensor = chooseSensor(yaml, requested);
  const bool fisheye = isFisheye(yaml);
  std::optional<KannalaBrandtCamera<double>> lens;
  if (fisheye) lens = readKannalaBrandt(yaml);
  const PinholeCamera<double> pinhole = fisheye ? lens->centralPinhole() : readPinhole(yaml);
  if (!fisheye) s.distortion = readDistortion(yaml);
  s.orb = readOrbParams(yaml);

  if (const auto fps = yaml.optionalReal("Camera.fps")) {
    if (*fps < 0) throw yaml.error("Camera.fps", "must not be negative");
    if (*fps > 0) s.fps = *fps;
  }
  if (const auto rgb = yaml.optionalInteger("Camera.RGB")) {
    if (*rgb != 0 && *rgb != 1) throw yaml.error("Camera.RGB", "expected 0 (BGR) or 1 (RGB)");
    s.rgbOrder = *rgb == 1;
  }
  // As ORB-SLAM3's settings: images (and the intrinsics) scaled to this width before extraction.
  if (yaml.has("Camera.newWidth")) s.newWidth = positiveInteger(yaml, "Camera.newWidth");
  if (const auto seed = yaml.optionalInteger("System.seed")) {
    if (*seed < 0) throw yaml.error("System.seed", "must not be negative");
    s.seed = static_cast<std::uint32_t>(*seed);
  }
  if (yaml.has("ThDepth")) s.thDepth = positive(yaml, "ThDepth");
  if (yaml.has("DepthMapFactor")) s.depthMapFactor = positive(yaml, "DepthMapFactor");
  if (yaml.has("DepthDisparitySigma")) s.depthDisparitySigma = positive(yaml, "DepthDisparitySigma");
  if (yaml.has("LEFT.K") || yaml.has("RIGHT.K")) {
    s.rectification = StereoRectificationBlocks{readBlock(yaml, "LEFT."), readBlock(yaml, "RIGHT.")};
  }

  switch (s.sensor) {
    case SensorKind::Monocular:
      if (lens) s.camera = *lens;
      else s.camera = pinhole;
      break;
    case SensorKind::Stereo:
    case SensorKind::Rgbd: {
      if (fisheye) {
        throw yaml.error("Camera.type", "a KannalaBrandt8 camera runs monocular here; a fisheye stereo pair is "
                                        "rectified to a pinhole pair on load from the dataset's calibration "
                                        "(EuRoC/TUM-VI sensor.yaml with distortion_model: equidistant), whose "
                                        "rectified camera is then used: drop --settings or give pinhole settings");
      }
      const double baseline = positive(yaml, "Camera.bf") / pinhole.fx;
      const double closeDepth = s.thDepth * baseline;
      if (s.sensor == SensorKind::Stereo) {
        s.camera = RectifiedStereoCamera<double>(pinhole, baseline, closeDepth);
      } else {
        if (!yaml.has("DepthMapFactor")) throw yaml.error("DepthMapFactor", "missing (required for rgbd)");
        RgbdCamera<double> rgbd(pinhole, baseline, s.depthMapFactor, closeDepth);
        rgbd.disparitySigma = s.depthDisparitySigma;
        s.camera = rgbd;
      }
      break;
    }
  }
  return s;
}

}  // namespace

std::span<const SettingsKey> settingsKeys() { return kSettingsKeys; }

Settings Settings::load(const std::filesystem::path& file) { return loadSettings(file, std::nullopt); }

Settings Settings::load(const std::filesystem::path& file, SensorKind sensor) { return loadSettings(file, sensor); }

StereoRectification Settings::stereoRectification() const {
  if (!rectification) throw keyError(source.string(), "LEFT.K", "missing: the file has no LEFT./RIGHT. rectification blocks");
  return rectificationFromBlocks(rectification->left, rectification->right, source.string());
}

}  // namespace orbis
