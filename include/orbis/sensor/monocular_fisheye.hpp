// orbis/sensor/monocular_fisheye.hpp — one fisheye camera: the MonocularFisheye sensor.
//
// Contract: MonocularFisheye is a SensorConfiguration for a Kannala–Brandt lens whose images
// arrive as the lens took them. ORB runs on the fisheye image (Monocular's builder: the same
// initialisation budget) and each keypoint's ray — the lens model's exact unprojection — is put
// on the lens's tangent plane (features/fisheye_features.hpp). Its camera, FisheyePlaneCamera,
// keeps the geometry on that plane (two-view initialisation, epipolar search, triangulation, PnP
// hypotheses) and everything that weighs pixel noise in the lens's pixels: bundle adjustment's
// residuals (motion-only, local, full, the initial pair's) and the loop's Sim(3) refinement go
// through the lens's projection and analytic Jacobian, the χ² gates of fusion and triangulation
// are taken there, and matching windows are widened by the lens's local stretch. Rays past
// maxKeypointAngle (default 80°; the plane ends at 90°) are not used. The pipeline is
// instantiated for this sensor (src/*/ explicit instantiations); the other sensors' code is
// untouched (if constexpr on ObservesThroughLens). docs/notes/2026-11-26-fisheye.md measures it.
#pragma once

#include <algorithm>
#include <numbers>

#include "orbis/camera/fisheye_plane_camera.hpp"
#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/features/fisheye_features.hpp"
#include "orbis/sensor/sensor.hpp"

namespace orbis {

// One fisheye camera: features through the Kannala–Brandt lens onto its tangent plane, residuals
// and gates in the lens's pixels.
struct MonocularFisheye {
  // @{
  // The lens on its tangent plane, the lens, the input and ORB-SLAM2's Huber kernel.
  using Camera = FisheyePlaneCamera<double>;
  using Lens = KannalaBrandtCamera<double>;
  using Input = MonocularInput;
  using RobustKernel = optim::HuberKernel;
  // @}
  // @{
  // As Monocular.
  static constexpr SensorKind kKind = SensorKind::Monocular;
  static constexpr bool kMetricScale = false;
  static constexpr bool kDepthFromSensor = false;
  static constexpr int kInitialisationBudgetFactor = Monocular::kInitialisationBudgetFactor;
  // @}
  // Keypoints farther off axis than this (degrees) are dropped.
  static constexpr double kDefaultMaxKeypointAngleDegrees = 80.0;

  // The sensor's camera for a lens.
  static Camera cameraOf(const Lens& lens) { return Camera::ofLens(lens); }

  // Keypoints through the lens onto its tangent plane, within maxAngle (radians) of the axis.
  struct KeypointsOnPlane {
    // @{
    // The lens and the widest angle kept.
    Lens lens;
    double maxAngle = 0;
    // @}
    // The image's features.
    FrameFeatures operator()(OrbExtractor& extractor, const cv::Mat& image) const {
      return extractFisheye(extractor, image, lens, maxAngle);
    }
  };

  // ORB on the raw fisheye image, keypoints through the lens; twice the budget while initialising.
  class FeatureBuilder : public MonocularFeatureBuilder<KeypointsOnPlane> {
   public:
    // Keypoints up to maxKeypointAngleDegrees off axis (at most 89: the plane ends at 90).
    FeatureBuilder(const Camera& camera, const OrbParams& orb,
                   double maxKeypointAngleDegrees = kDefaultMaxKeypointAngleDegrees)
        : MonocularFeatureBuilder<KeypointsOnPlane>(
              {camera.lens, std::min(maxKeypointAngleDegrees, 89.0) * std::numbers::pi / 180.0}, orb) {}
  };
};

static_assert(SensorConfiguration<MonocularFisheye>);

}  // namespace orbis
