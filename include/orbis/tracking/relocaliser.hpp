// orbis/tracking/relocaliser.hpp — finding a lost camera in the map again (paper §III-F;
// ORB-SLAM §V-C), and the PnP solver it needs.
//
// Contract:
//  - solveEpnp(world, pixels, K) estimates the camera-from-world pose from n >= 4 world points
//    and their undistorted pixels by EPnP (Lepetit, Moreno-Noguer, Fua 2009: four control
//    points, the 12-d null space of M, the three beta approximations refined by Gauss-Newton,
//    the one with the least reprojection error kept). Returns false for degenerate input.
//  - solvePnpRansac runs EPnP on random 5-point sets drawn from the caller's generator (so the
//    result is a function of the input and the seed), counts inliers by the chi-square test
//    (5.991 × σ² of the keypoint's level), stops when the 0.99-probability bound is met, and
//    refines the best model on all its inliers.
//  - Relocaliser::relocalise(frame) (caller holds Map::mutex(), frame BoW computed): candidates
//    from the keyframe database, BoW matches (ratio 0.75) with each, EPnP-RANSAC on those with
//    at least 15 matches, motion-only BA, search by projection for more matches and BA again;
//    accepted at 50 inliers. On success the frame holds the pose and its inlier matches
//    (outliers cleared) and true is returned; on failure the frame's matches are cleared.
//    Candidates are tried in the database's deterministic order; the RANSAC generator is seeded
//    from (seed, frame index), so a run is reproducible whatever happened before. Templated on
//    the sensor (its camera projects, its kernel weighs motion-only BA); bodies in
//    relocaliser_impl.hpp, the built-in sensors compiled in src/tracking/relocaliser.cpp.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/StdVector>

#include "orbis/bow/keyframe_database.hpp"
#include "orbis/map/map.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/map/frame.hpp"
#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/sensor/sensor.hpp"

namespace orbis {

// @{
// Eigen-aligned vectors of points and pixels.
using Vector3dList = std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>>;
using Vector2dList = std::vector<Eigen::Vector2d, Eigen::aligned_allocator<Eigen::Vector2d>>;
// @}

// EPnP: the pose of a camera from 3-D world points and their pixels; false when degenerate.
bool solveEpnp(const Vector3dList& world, const Vector2dList& pixels, const PinholeCamera<double>& K, SE3d& Tcw);

// The relocaliser's PnP RANSAC.
struct PnpRansacParams {
  // @{
  // Confidence, inliers required and the iteration cap.
  double probability = 0.99;
  int minInliers = 10;
  int maxIterations = 300;
  // @}
  double chi2 = 5.991;  // 2-dof, 95%
};

// A PnP RANSAC result.
struct PnpRansacResult {
  // @{
  // Whether a pose was found, and the pose.
  bool found = false;
  SE3d Tcw;
  // @}
  std::vector<char> inlier;  // per correspondence
  // Correspondences agreeing with it.
  int inliers = 0;
};

// sigma2[i]: variance of pixel i's measurement (its pyramid level's σ²).
PnpRansacResult solvePnpRansac(const Vector3dList& world, const Vector2dList& pixels,
                               const std::vector<float>& sigma2, const PinholeCamera<double>& K,
                               const PnpRansacParams& params, std::mt19937_64& rng);

// Relocalisation thresholds (ORB-SLAM2's).
struct RelocaliserOptions {
  // @{
  // Bag-of-words ratio, matches a candidate needs, inliers to accept, RANSAC seed and settings.
  float bowRatio = 0.75f;
  int minBowMatches = 15;
  int acceptInliers = 50;
  std::uint64_t seed = 0;
  PnpRansacParams ransac;
  // @}
};

// Relocalisation counters.
struct RelocalisationStats {
  // @{
  // Attempts and successes.
  std::size_t attempts = 0, successes = 0;
  // @}
  // Candidates of the last attempt.
  std::size_t lastCandidates = 0;
  KeyFrameId lastKeyFrame = 0;  // the keyframe the last success matched
};

// Relocalisation (§III-F): keyframe candidates by bag of words, PnP RANSAC, then guided search and
// motion-only BA over the candidate's neighbourhood.
template <SensorConfiguration Sensor>
class Relocaliser {
 public:
  // The sensor's frame type.
  using FrameT = Frame<typename Sensor::Camera>;

  // Relocalises in map through the keyframe database.
  Relocaliser(const Map& map, const bow::KeyframeDatabase& database, RelocaliserOptions options = {})
      : map_(map), database_(database), options_(options) {}

  // Sets the frame's pose and matches when it finds itself in the map again.
  bool relocalise(FrameT& frame);
  // Attempts and successes so far.
  const RelocalisationStats& stats() const { return stats_; }

 private:
  // Covisible keyframes of a candidate whose points the guided search also projects (as many as
  // the tracker's local map takes from each of its keyframes).
  static constexpr std::size_t kCovisiblesSearched = 10;
  // Pose and matches of `frame` from one candidate's BoW matches; false when rejected.
  bool tryCandidate(FrameT& frame, const KeyFrame& kf, const std::vector<MapPoint*>& bowMatches,
                    std::mt19937_64& rng) const;

  const Map& map_;
  const bow::KeyframeDatabase& database_;
  RelocaliserOptions options_;
  RelocalisationStats stats_;
};

}  // namespace orbis

#include "orbis/tracking/relocaliser_impl.hpp"

namespace orbis {
extern template class Relocaliser<Stereo>;
extern template class Relocaliser<Rgbd>;
extern template class Relocaliser<Monocular>;
extern template class Relocaliser<MonocularFisheye>;
}  // namespace orbis
