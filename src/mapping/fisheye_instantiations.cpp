// Local mapping for a fisheye lens, apart from the other sensors' (its own translation unit:
// the builds compile it in parallel).
#include "orbis/mapping/local_mapper.hpp"

namespace orbis {

template class LocalMapper<MonocularFisheye>;

}  // namespace orbis
