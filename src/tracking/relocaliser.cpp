// Relocaliser<Sensor> for the built-in sensors.
#include "orbis/tracking/relocaliser.hpp"

namespace orbis {

template class Relocaliser<Stereo>;
template class Relocaliser<Rgbd>;
template class Relocaliser<Monocular>;

}  // namespace orbis
