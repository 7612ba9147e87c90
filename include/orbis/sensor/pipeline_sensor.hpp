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

template <class S>
struct PipelineSensorOf {
  using type = S;
};

template <class S>
  requires requires { typename S::PipelineSensor; }
struct PipelineSensorOf<S> {
  using type = typename S::PipelineSensor;
  static_assert(std::same_as<typename S::Camera, typename type::Camera> &&
                std::same_as<typename S::Input, typename type::Input>);
};

template <class S>
using PipelineSensor = typename PipelineSensorOf<S>::type;

}  // namespace orbis
