// LocalMapper<Sensor> for the built-in sensors.
#include "orbis/mapping/local_mapper.hpp"

namespace orbis {

template class LocalMapper<Stereo>;
template class LocalMapper<Rgbd>;
template class LocalMapper<Monocular>;

}  // namespace orbis
