// LoopCloser<Sensor> for the built-in sensors.
#include "orbis/loop/loop_closer.hpp"

namespace orbis {

template class LoopCloser<Stereo>;
template class LoopCloser<Rgbd>;
template class LoopCloser<Monocular>;

}  // namespace orbis
