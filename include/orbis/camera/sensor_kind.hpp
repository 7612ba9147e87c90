// orbis/camera/sensor_kind.hpp — the three sensor configurations of the paper, as a runtime tag.
//
// Contract: used only at the boundary (settings files, dataset readers, command line) to pick a
// compile-time sensor configuration once; the pipeline itself is templated on the sensor.
#pragma once

namespace orbis {

enum class SensorKind { Monocular, Stereo, Rgbd };

}  // namespace orbis
