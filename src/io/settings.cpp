// ORB-SLAM2 settings reader; see orbis/io/settings.hpp.
#include "orbis/io/settings.hpp"

#include "../camera/yaml_reader.hpp"

namespace orbis {

namespace {

using detail::YamlReader;

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
  if (std::min(d.rows(), d.cols()) != 1 || (d.size() != 4 && d.size() != 5)) {
    throw yaml.error(prefix + "D", "expected 4 or 5 distortion coefficients k1 k2 p1 p2 [k3] in one row");
  }
  block.D = {d(0), d(1), d(2), d(3), d.size() == 5 ? d(4) : 0.0};
  block.R = yaml.matrix(prefix + "R", 3, 3);
  block.P = yaml.matrix(prefix + "P", 3, 4);
  block.width = positiveInteger(yaml, prefix + "width");
  block.height = positiveInteger(yaml, prefix + "height");
  if (!(block.K(0, 0) > 0 && block.K(1, 1) > 0)) throw yaml.error(prefix + "K", "focal lengths must be positive");
  return block;
}

Settings loadSettings(const std::filesystem::path& file, std::optional<SensorKind> requested) {
  const YamlReader yaml(file);
  Settings s;
  s.source = file;
  s.sensor = chooseSensor(yaml, requested);
  const PinholeCamera<double> pinhole = readPinhole(yaml);
  s.distortion = readDistortion(yaml);
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
      s.camera = pinhole;
      break;
    case SensorKind::Stereo:
    case SensorKind::Rgbd: {
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

Settings Settings::load(const std::filesystem::path& file) { return loadSettings(file, std::nullopt); }

Settings Settings::load(const std::filesystem::path& file, SensorKind sensor) { return loadSettings(file, sensor); }

StereoRectification Settings::stereoRectification() const {
  if (!rectification) throw keyError(source.string(), "LEFT.K", "missing: the file has no LEFT./RIGHT. rectification blocks");
  return rectificationFromBlocks(rectification->left, rectification->right, source.string());
}

}  // namespace orbis
