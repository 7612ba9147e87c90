// orbis/camera/sensor_kind.hpp — the three sensor configurations of the paper, as a runtime tag.
//
// Contract: used only at the boundary (settings files, dataset readers, command line) to pick a
// compile-time sensor configuration once; the pipeline itself is templated on the sensor. This
// is the one place a sensor's name is read or written: parseSensorKind accepts "mono" or
// "monocular", "stereo", "rgbd" or "rgb-d", in any letter case, and throws orbis::Error for
// anything else; toString gives the short name ("mono", "stereo", "rgbd"), which parses back.
#pragma once

#include <string>
#include <string_view>

namespace orbis {

// The three sensor families: one camera, a rectified stereo pair, a colour camera with a depth
// sensor.
enum class SensorKind { Monocular, Stereo, Rgbd };

// source and where name the origin in the error, as orbis::Error does: a file and "key Sensor",
// or "argument --sensor" and nothing.
SensorKind parseSensorKind(std::string_view name, const std::string& source = "sensor",
                           const std::string& where = "");
// "mono", "stereo" or "rgbd".
std::string_view toString(SensorKind sensor);

}  // namespace orbis
