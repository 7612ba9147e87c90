// SlamCore<Sensor> for the built-in sensors.
#include "orbis/system/slam_core.hpp"

namespace orbis {

template class SlamCore<Stereo>;
template class SlamCore<Rgbd>;
template class SlamCore<Monocular>;

}  // namespace orbis
