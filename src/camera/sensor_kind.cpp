// Sensor names; see orbis/camera/sensor_kind.hpp.
#include "orbis/camera/sensor_kind.hpp"

#include "orbis/util/enum_names.hpp"

namespace orbis {

namespace {
// First row of a value: the name written back.
constexpr EnumName<SensorKind> kSensorNames[] = {
    {SensorKind::Monocular, "mono"}, {SensorKind::Monocular, "monocular"}, {SensorKind::Stereo, "stereo"},
    {SensorKind::Rgbd, "rgbd"},      {SensorKind::Rgbd, "rgb-d"},
};
}  // namespace

SensorKind parseSensorKind(std::string_view name, const std::string& source, const std::string& where) {
  return parseEnumName(kSensorNames, name, "sensor", source, where, LetterCase::Ignored);
}

std::string_view toString(SensorKind sensor) { return enumName(kSensorNames, sensor); }

}  // namespace orbis
