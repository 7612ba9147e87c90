// orbis/sensor/pipeline_sensor.hpp — which sensor configuration's pipeline a configuration's
// frames run through.
//
// Contract: PipelineSensor<S> is S itself, unless S names a PipelineSensor with the same Camera
// and Input: a sensor that differs from another only in how it builds frames (MonocularFisheye,
// whose frames are tangent-plane monocular frames) reuses that sensor's tracking, mapping and
// loop closing instead of instantiating a second copy of the pipeline.
#pragma once

#include <concepts>

namespace orbis {

// The sensor configuration the pipeline is instantiated for: the sensor itself, or its
// PipelineSensor.
template <class S>
struct PipelineSensorOf {
  // The sensor.
  using type = S;
};

// A sensor that runs on another's pipeline (MonocularFisheye on Monocular's).
template <class S>
  requires requires { typename S::PipelineSensor; }
struct PipelineSensorOf<S> {
  // That sensor.
  using type = typename S::PipelineSensor;
  static_assert(std::same_as<typename S::Camera, typename type::Camera> &&
                std::same_as<typename S::Input, typename type::Input>);
};

// The pipeline's sensor of S.
template <class S>
using PipelineSensor = typename PipelineSensorOf<S>::type;

}  // namespace orbis
