// orbis/tracking/pose_optimizer.hpp — motion-only BA of a frame against its matched map points.
//
// Contract: optimizePose<Kernel> refines frame.Tcw from its matches (optim::motionOnlyBundleAdjustment
// on the frame's camera model: mono, stereo or depth residuals as it calls for, the robust kernel
// Kernel — the sensor's — information 1/σ² of the keypoint's level; keypoints beyond the camera's
// bundleAdjustmentDepthLimit as monocular) in ORB-SLAM's four rounds
// with χ² outlier classification (5.991 mono, 7.815 stereo and depth), writes frame.outlier for
// every matched keypoint and returns the number of inliers. Frames with fewer than 3 matches are
// left untouched (returns 0). Caller holds Map::mutex() (point positions are read).
#pragma once

#include <vector>

#include "orbis/map/frame.hpp"
#include "orbis/optim/slam_ba.hpp"

namespace orbis {

// Motion-only BA of a frame against its matched map points (ORB-SLAM2's PoseOptimization); marks
// outliers and returns the inliers.
template <optim::RobustKernel Kernel = optim::HuberKernel, CameraModel Camera>
int optimizePose(Frame<Camera>& frame) {
  const FrameFeatures& f = *frame.features;
  std::vector<Eigen::Vector3d> points;
  std::vector<optim::SlamObservation> observations;
  std::vector<std::size_t> keypointOf;  // observation -> keypoint
  points.reserve(frame.size());
  observations.reserve(frame.size());
  keypointOf.reserve(frame.size());
  const double depthLimit = bundleAdjustmentDepthLimit(*frame.camera);
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (!p) continue;
    frame.outlier[i] = 0;
    const Keypoint& k = f.keypointsUn[i];
    const double uRight = f.depth[i] > depthLimit ? -1.0 : f.uRight[i];  // far: monocular
    observations.push_back({0, static_cast<int>(points.size()), Eigen::Vector3d(k.u, k.v, uRight),
                            f.scales.invSigma2[static_cast<std::size_t>(k.octave)]});
    points.push_back(p->position());
    keypointOf.push_back(i);
  }
  if (observations.size() < 3) return 0;
  // ORB-SLAM's schedule (optim::MotionOnlyOptions' defaults): four rounds of 10 iterations from the
  // prior pose, reclassifying every observation by its χ² after each; the last without kernel.
  const optim::MotionOnlyResult result =
      optim::motionOnlyBundleAdjustment<Kernel>(*frame.camera, frame.Tcw, points, observations);
  for (std::size_t k = 0; k < observations.size(); ++k) frame.outlier[keypointOf[k]] = result.outlier[k];
  return result.inliers;
}

}  // namespace orbis
