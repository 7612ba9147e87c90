// Sensor names; see orbis/camera/sensor_kind.hpp.
#include "orbis/camera/sensor_kind.hpp"

#include <algorithm>
#include <cctype>

#include "orbis/util/error.hpp"

namespace orbis {

SensorKind parseSensorKind(std::string_view name, const std::string& source, const std::string& where) {
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  if (lower == "mono" || lower == "monocular") return SensorKind::Monocular;
  if (lower == "stereo") return SensorKind::Stereo;
  if (lower == "rgbd" || lower == "rgb-d") return SensorKind::Rgbd;
  throw Error(source, where,
              "expected mono, monocular, stereo, rgbd or rgb-d (any letter case), found \"" + std::string(name) + "\"");
}

std::string_view toString(SensorKind sensor) {
  switch (sensor) {
    case SensorKind::Monocular: return "mono";
    case SensorKind::Stereo: return "stereo";
    case SensorKind::Rgbd: return "rgbd";
  }
  return "unknown";
}

}  // namespace orbis
