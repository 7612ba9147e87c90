// orbis/tracking/pose_optimizer.hpp — motion-only BA of a frame against its matched map points.
//
// Contract: optimizePose refines frame.Tcw from its matches (optim::motionOnlyBundleAdjustment:
// mono, stereo or depth residuals as the frame's camera calls for, Huber kernel, information
// 1/σ² of the keypoint's level) in ORB-SLAM's four rounds with χ² outlier classification
// (5.991 mono, 7.815 stereo and depth), writes frame.outlier for every matched keypoint and
// returns the number of inliers. Frames with fewer than 3 matches are left
// untouched (returns 0). Caller holds Map::mutex() (point positions are read).
#pragma once

#include "orbis/tracking/frame.hpp"

namespace orbis {

int optimizePose(Frame& frame);

}  // namespace orbis
