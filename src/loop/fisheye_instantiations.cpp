// Loop closing for a fisheye lens, apart from the other sensors' (its own translation unit:
// the builds compile it in parallel).
#include "orbis/loop/loop_closer.hpp"

namespace orbis {

template class LoopCloser<MonocularFisheye>;

}  // namespace orbis
