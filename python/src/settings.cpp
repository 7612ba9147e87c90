// python/src/settings.cpp — orbis.Settings (ORB-SLAM2 settings files) and orbis.OrbParams.
//
// Contract: Settings.load(path, sensor=None) is orbis::Settings::load: a missing file raises
// orbis.MissingFileError, a missing or malformed key orbis.Error naming file and key, an unknown
// sensor name ValueError. The loaded values stay editable (e.g. settings.orb.features = 500)
// before a Slam is built from them; the camera is described as a dict (describeCamera).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <sstream>
#include <type_traits>

#include "bindings.hpp"
#include "errors.hpp"
#include "orbis/adapters/dataset.hpp"
#include "orbis/io/settings.hpp"

namespace orbis::python {

using namespace pybind11::literals;

SensorKind sensorArgument(const std::string& name) {
  if (name == "mono" || name == "monocular") return SensorKind::Monocular;
  if (name == "stereo") return SensorKind::Stereo;
  if (name == "rgbd") return SensorKind::Rgbd;
  throw py::value_error("sensor: expected 'mono', 'stereo' or 'rgbd', got '" + name + "'");
}

py::dict describeCamera(const CameraVariant& camera) {
  return std::visit(
      [](const auto& c) {
        using C = std::decay_t<decltype(c)>;
        py::dict d;
        const PinholeCamera<double>* pinhole = nullptr;
        [[maybe_unused]] PinholeCamera<double> central;
        if constexpr (std::is_same_v<C, PinholeCamera<double>>) {
          d["model"] = "pinhole";
          pinhole = &c;
        } else if constexpr (std::is_same_v<C, KannalaBrandtCamera<double>>) {
          d["model"] = "kannala_brandt";
          d["k1"] = c.k1, d["k2"] = c.k2, d["k3"] = c.k3, d["k4"] = c.k4;
          d["max_angle_deg"] = c.maxAngle * 180.0 / M_PI;
          central = c.centralPinhole();
          pinhole = &central;
        } else {
          d["model"] = std::is_same_v<C, RgbdCamera<double>> ? "rgbd" : "stereo";
          pinhole = &c.pinhole;
          d["baseline"] = c.baseline;
          d["bf"] = c.bf();
          d["close_depth"] = c.closeDepth;
        }
        if constexpr (std::is_same_v<C, RgbdCamera<double>>) {
          d["depth_scale"] = c.depthScale;
          d["disparity_sigma"] = c.disparitySigma;
        }
        d["fx"] = pinhole->fx, d["fy"] = pinhole->fy, d["cx"] = pinhole->cx, d["cy"] = pinhole->cy;
        d["width"] = pinhole->width, d["height"] = pinhole->height;
        return d;
      },
      camera);
}

namespace {

std::string orbParamsRepr(const OrbParams& p) {
  std::ostringstream s;
  s << "OrbParams(features=" << p.features << ", scale_factor=" << p.scaleFactor << ", levels=" << p.levels
    << ", ini_th_fast=" << p.iniThFast << ", min_th_fast=" << p.minThFast
    << ", right_features_factor=" << p.rightFeaturesFactor << ")";
  return s.str();
}

void bindOrbParams(py::module_& m) {
  py::class_<OrbParams>(m, "OrbParams", "Parameters of the ORB extractor (settings keys ORBextractor.*).")
      .def(py::init<>(), "ORB-SLAM2's defaults: 1000 features, 8 levels of scale 1.2, FAST 20 / 7.")
      .def_readwrite("features", &OrbParams::features, "Keypoint budget over all pyramid levels.")
      .def_readwrite("scale_factor", &OrbParams::scaleFactor, "Ratio between consecutive pyramid levels.")
      .def_readwrite("levels", &OrbParams::levels, "Number of pyramid levels.")
      .def_readwrite("ini_th_fast", &OrbParams::iniThFast, "FAST threshold tried first in each grid cell.")
      .def_readwrite("min_th_fast", &OrbParams::minThFast, "Fallback FAST threshold for empty cells.")
      .def_readwrite("right_features_factor", &OrbParams::rightFeaturesFactor,
                     "Stereo: the right image's budget is features times this.")
      .def("__repr__", &orbParamsRepr);
}

}  // namespace

void bindSettings(py::module_& m) {
  bindOrbParams(m);
  py::class_<Settings>(m, "Settings",
                       "An ORB-SLAM2 settings file (YAML): camera, ORBextractor.*, ThDepth, DepthMapFactor,\n"
                       "plus orbis's optional Sensor, System.seed, DepthDisparitySigma keys.")
      .def_static(
          "load",
          [](const std::filesystem::path& path, std::optional<std::string> sensor) {
            requireFile(path);
            std::optional<SensorKind> kind;
            if (sensor) kind = sensorArgument(*sensor);
            py::gil_scoped_release release;
            return kind ? Settings::load(path, *kind) : Settings::load(path);
          },
          "path"_a, "sensor"_a = py::none(),
          "Reads a settings file. sensor ('mono', 'stereo' or 'rgbd') overrides the file's Sensor key\n"
          "and what its keys imply. Raises MissingFileError, or orbis.Error naming file and key.")
      .def_property_readonly("source", [](const Settings& s) { return s.source; }, "The file read.")
      .def_property_readonly("sensor", [](const Settings& s) { return std::string(toString(s.sensor)); },
                             "'mono', 'stereo' or 'rgbd'.")
      .def_property_readonly("camera", [](const Settings& s) { return describeCamera(s.camera); },
                             "The camera as a dict: model, fx, fy, cx, cy, width, height (+ baseline, bf,\n"
                             "close_depth for stereo and RGB-D; depth_scale, disparity_sigma for RGB-D).")
      .def_property_readonly(
          "distortion",
          [](const Settings& s) {
            const auto& d = s.distortion;
            return py::make_tuple(d.k1, d.k2, d.p1, d.p2, d.k3);
          },
          "(k1, k2, p1, p2, k3) of the input images; zeros when they are rectified.")
      .def_readwrite("orb", &Settings::orb, "ORB extractor parameters (editable before a Slam is built).")
      .def_readwrite("fps", &Settings::fps, "Camera.fps: the keyframe rule's frame rate (editable).")
      .def_readonly("rgb_order", &Settings::rgbOrder, "Camera.RGB: colour images arrive as RGB (True) or BGR.")
      .def_readonly("th_depth", &Settings::thDepth, "ThDepth: close/far threshold in baselines.")
      .def_readonly("depth_map_factor", &Settings::depthMapFactor, "DepthMapFactor: raw depth / factor = metres.")
      .def_readonly("seed", &Settings::seed, "System.seed (Slam objects take their seed argument instead, as `orbis run` does).")
      .def("__repr__", [](const Settings& s) {
        return "Settings(source='" + s.source.string() + "', sensor='" + std::string(toString(s.sensor)) + "')";
      });
  m.def(
      "settings_keys",
      [] {
        py::list keys;
        for (const SettingsKey& k : settingsKeys())
          keys.append(py::dict("name"_a = k.name, "type"_a = k.type, "meaning"_a = k.meaning));
        return keys;
      },
      "Every settings key Settings.load reads, as dicts of name, type and meaning (`orbis settings-keys`).");
}

}  // namespace orbis::python
