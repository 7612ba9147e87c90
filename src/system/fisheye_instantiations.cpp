// The SLAM core for a fisheye lens, apart from the other sensors' (its own translation unit:
// the builds compile it in parallel).
#include "orbis/system/slam_core.hpp"

namespace orbis {

template class SlamCore<MonocularFisheye>;

}  // namespace orbis
