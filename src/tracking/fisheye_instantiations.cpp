// The tracker and relocaliser for a fisheye lens, apart from the other sensors' (their own
// translation unit: the builds compile them in parallel).
#include "orbis/tracking/tracker.hpp"
#include "orbis/tracking/relocaliser.hpp"

namespace orbis {

template class Tracker<MonocularFisheye>;
template class Relocaliser<MonocularFisheye>;

}  // namespace orbis
