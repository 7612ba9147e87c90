// The tracker's non-template parts and its instantiations for the built-in sensors.
#include "orbis/tracking/tracker.hpp"

namespace orbis {

const char* toString(TrackingState s) {
  switch (s) {
    case TrackingState::NotInitialised: return "not-initialised";
    case TrackingState::Ok: return "ok";
    case TrackingState::Lost: return "lost";
  }
  return "?";
}

SE3d worldPoseOf(const TrackedFrame& f) {
  // A culled reference keyframe hangs from its parent by the relative pose it had when culled.
  const KeyFrame* kf = f.reference;
  SE3d Trw;  // reference-from-world, accumulated up the spanning tree
  SE3d chain;
  while (kf->isBad() && kf->parent()) {
    chain = chain * kf->poseRelativeToParent();
    kf = kf->parent();
  }
  Trw = chain * kf->Tcw();
  return f.Tcr * Trw;
}

template class Tracker<Stereo>;
template class Tracker<Rgbd>;
template class Tracker<Monocular>;

}  // namespace orbis
