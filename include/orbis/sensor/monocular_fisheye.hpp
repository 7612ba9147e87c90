// orbis/sensor/monocular_fisheye.hpp — one fisheye camera: the MonocularFisheye sensor.
//
// Contract: MonocularFisheye is a SensorConfiguration for a Kannala-Brandt lens
// (KannalaBrandtCamera) whose images arrive as the lens took them. ORB runs on the fisheye image
// and each keypoint's ray — the lens model's exact unprojection — is put on the lens's tangent
// plane (features/fisheye_features.hpp), the pinhole with the lens's fx, fy, cx, cy (its Camera),
// where matching windows, epipolar geometry, PnP, triangulation and bundle adjustment work as on
// any monocular frame: its PipelineSensor is Monocular, so tracking, mapping and loop closing are
// Monocular's own instantiations. The rays are exact (no image resampling, no approximation of
// the lens); the noise is not: a keypoint θ off axis has its pixel error stretched by up to
// 1/cos²θ radially on the plane while bundle adjustment weights it by its pyramid level alone,
// and rays past maxKeypointAngle (default 70°; the plane ends at 90°) are not used.
// docs/notes/2026-11-26-fisheye.md measures what that costs and compares it with ORB-SLAM3's
// residuals through the lens.
#pragma once

#include <algorithm>
#include <numbers>

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/features/fisheye_features.hpp"
#include "orbis/sensor/pipeline_sensor.hpp"
#include "orbis/sensor/sensor.hpp"

namespace orbis {

struct MonocularFisheye {
  using Camera = PinholeCamera<double>;  // the lens's tangent plane
  using PipelineSensor = Monocular;
  using Lens = KannalaBrandtCamera<double>;
  using Input = MonocularInput;
  using RobustKernel = optim::HuberKernel;
  static constexpr SensorKind kKind = SensorKind::Monocular;
  static constexpr bool kMetricScale = false;
  static constexpr bool kDepthFromSensor = false;
  static constexpr int kInitialisationBudgetFactor = Monocular::kInitialisationBudgetFactor;
  static constexpr double kDefaultMaxKeypointAngleDegrees = 70.0;

  // The tangent-plane pinhole a lens gives the pipeline.
  static Camera planeOf(const Lens& lens) { return lens.centralPinhole(); }

  class FeatureBuilder {
   public:
    // `camera` is planeOf(lens), the pipeline's camera; the builder works from the lens.
    FeatureBuilder(const Camera& /*camera*/, const OrbParams& orb, const Lens& lens,
                   double maxKeypointAngleDegrees = kDefaultMaxKeypointAngleDegrees)
        : lens_(lens),
          maxAngle_(std::min(maxKeypointAngleDegrees, 89.0) * std::numbers::pi / 180.0),
          trackingExtractor_(orb),
          initialisationExtractor_(initialisationParams(orb)) {}
    FrameFeatures build(const Input& in) {
      return extractFisheye(isInitialising_ ? initialisationExtractor_ : trackingExtractor_, in.image, lens_, maxAngle_);
    }
    void setInitialising(bool initialising) { isInitialising_ = initialising; }
    bool initialising() const { return isInitialising_; }

   private:
    static OrbParams initialisationParams(OrbParams orb) {
      orb.features *= kInitialisationBudgetFactor;
      return orb;
    }
    Lens lens_;
    double maxAngle_;
    OrbExtractor trackingExtractor_, initialisationExtractor_;
    bool isInitialising_ = true;
  };
};

static_assert(SensorConfiguration<MonocularFisheye>);

}  // namespace orbis
