#include "orbis/tracking/pose_optimizer.hpp"

#include <vector>

#include "orbis/map/map_camera.hpp"
#include "orbis/optim/slam_ba.hpp"

namespace orbis {

int optimizePose(Frame& frame) {
  const FrameFeatures& f = *frame.features;
  std::vector<Eigen::Vector3d> points;
  std::vector<optim::SlamObservation> observations;
  std::vector<std::size_t> keypointOf;  // observation -> keypoint
  points.reserve(frame.size());
  observations.reserve(frame.size());
  keypointOf.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (!p) continue;
    frame.outlier[i] = 0;
    const Keypoint& k = f.keypointsUn[i];
    observations.push_back({0, static_cast<int>(points.size()), Eigen::Vector3d(k.u, k.v, f.uRight[i]),
                            f.scales.invSigma2[static_cast<std::size_t>(k.octave)]});
    points.push_back(p->position());
    keypointOf.push_back(i);
  }
  if (observations.size() < 3) return 0;
  // ORB-SLAM's schedule (optim::MotionOnlyOptions' defaults): four rounds of 10 iterations from the
  // prior pose, reclassifying every observation by its χ² after each; the last without kernel.
  const optim::MotionOnlyResult result = visitCamera(frame.intrinsics, [&](const auto& camera) {
    return optim::motionOnlyBundleAdjustment(camera, frame.Tcw, points, observations);
  });
  for (std::size_t k = 0; k < observations.size(); ++k) frame.outlier[keypointOf[k]] = result.outlier[k];
  return result.inliers;
}

}  // namespace orbis
