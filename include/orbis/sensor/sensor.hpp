// orbis/sensor/sensor.hpp — sensor configurations: the compile-time traits the whole pipeline
// runs on (frames, tracking, local mapping, loop closing, bundle adjustment, Slam<Sensor>).
//
// Contract: a sensor configuration names its camera model (a CameraModel; metric sensors a
// StereoCameraModel), the input one frame brings, how that input becomes FrameFeatures (paper
// Fig. 2b), the robust kernel every bundle adjustment uses (an optim::RobustKernel), and three
// facts the pipeline branches on at compile time: kKind, kMetricScale (depth from one frame:
// one-frame bootstrap, SE(3) loops) and kDepthFromSensor (an RGB-D sensor rather than a stereo
// pair: wider search windows, the depth residual). A new sensor is one more struct meeting
// SensorConfiguration, instantiated from the headers (see tests/system/custom_sensor_test.cpp),
// not a fork of the pipeline.
#pragma once

#include <algorithm>
#include <concepts>
#include <utility>

#include <opencv2/core.hpp>

#include "orbis/camera/camera_model.hpp"
#include "orbis/camera/distortion.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/sensor_kind.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/features/stereo_matcher.hpp"
#include "orbis/optim/robust_kernel.hpp"

namespace orbis {

// A monocular frame.
struct MonocularInput {
  // Seconds.
  double timestamp = 0;
  cv::Mat image;  // 8-bit grey or BGR, as the lens took it (the builder undistorts keypoints)
};

// A stereo frame.
struct StereoInput {
  // Seconds.
  double timestamp = 0;
  // @{
  // The left and right images.
  cv::Mat left, right;  // rectified, 8-bit grey or BGR
  // @}
};

// An RGB-D frame.
struct RgbdInput {
  // Seconds.
  double timestamp = 0;
  cv::Mat image;  // 8-bit grey or BGR
  cv::Mat depth;  // CV_32F metres, or CV_16U raw (divided by the camera's depthScale); 0 = none
};

template <class S>
concept SensorConfiguration = requires(typename S::FeatureBuilder& builder, const typename S::Input& input) {
  typename S::Camera;
  typename S::Input;
  typename S::RobustKernel;
  { S::kKind } -> std::convertible_to<SensorKind>;
  { S::kMetricScale } -> std::convertible_to<bool>;
  { S::kDepthFromSensor } -> std::convertible_to<bool>;
  { builder.build(input) } -> std::same_as<FrameFeatures>;
} && CameraModel<typename S::Camera> && optim::RobustKernel<typename S::RobustKernel> &&
    (!S::kMetricScale || StereoCameraModel<typename S::Camera>);

// A rectified stereo pair: ORB on both images, then stereo matching along rows (§III-A); the
// two extractions run in parallel. OrbParams::rightFeaturesFactor (settings key
// ORBextractor.rightFeaturesFactor) scales the right image's budget. The default keeps
// ORB-SLAM2's equal budgets: a larger right budget matches more keypoints but, through the
// paper's keyframe rule, makes fewer keyframes and measured worse
// (docs/notes/2026-11-23-stereo-right-features-factor.md).
struct Stereo {
  // @{
  // The rectified pair's camera and its input.
  using Camera = RectifiedStereoCamera<double>;
  using Input = StereoInput;
  // @}
  using RobustKernel = optim::HuberKernel;  // ORB-SLAM2's, with χ² 95% thresholds
  // @{
  // Stereo measures metric depth itself, from the disparity.
  static constexpr SensorKind kKind = SensorKind::Stereo;
  static constexpr bool kMetricScale = true;
  static constexpr bool kDepthFromSensor = false;
  // @}

  // ORB on both images (in parallel), then stereo matching along rows.
  class FeatureBuilder {
   public:
    // Extractors for the left image and (rightFeaturesFactor times the budget) the right.
    FeatureBuilder(const Camera& camera, const OrbParams& orb)
        : camera_(camera), left_(orb), right_(rightParams(orb)) {
      matcher_.setParallel(true);  // after the two extractions, which ran one per core
    }
    // The frame's features.
    FrameFeatures build(const Input& in) { return extractStereo(left_, right_, in.left, in.right, camera_, matcher_); }

   private:
    static OrbParams rightParams(OrbParams orb) {
      orb.features *= std::max(1, orb.rightFeaturesFactor);
      return orb;
    }
    Camera camera_;
    OrbExtractor left_, right_;
    StereoMatcher matcher_;
  };
};

// An RGB-D camera: ORB on the colour image, depth turned into a virtual right coordinate.
struct Rgbd {
  // @{
  // The depth camera, its input and ORB-SLAM2's Huber kernel.
  using Camera = RgbdCamera<double>;
  using Input = RgbdInput;
  using RobustKernel = optim::HuberKernel;
  // @}
  // @{
  // Depth comes from the sensor, in metres.
  static constexpr SensorKind kKind = SensorKind::Rgbd;
  static constexpr bool kMetricScale = true;
  static constexpr bool kDepthFromSensor = true;
  // @}

  // ORB on the colour image, depth looked up per keypoint.
  class FeatureBuilder {
   public:
    // An extractor for the colour image.
    FeatureBuilder(const Camera& camera, const OrbParams& orb) : camera_(camera), metric_(camera), extractor_(orb) {
      metric_.depthScale = 1.0;
      extractor_.setParallelLevels(true);  // one image per frame: its levels use both cores
    }
    // The frame's features.
    FrameFeatures build(const Input& in) {
      return extractRgbd(extractor_, in.image, in.depth, in.depth.depth() == CV_32F ? metric_ : camera_);
    }

   private:
    Camera camera_, metric_;  // metric_: the same camera reading depth already in metres
    OrbExtractor extractor_;
  };
};

// The builder every monocular sensor shares (paper Fig. 2b for one image): ORB on the image with
// the tracking budget, or with kInitialisationBudget times it while initialising() (see
// Monocular), each extractor's pyramid levels on both cores; KeypointsOf turns an extractor's
// keypoints into the frame's features (a callable (OrbExtractor&, const cv::Mat&) ->
// FrameFeatures: undistorted with a RadTan lens, or put on a fisheye's tangent plane).
template <class KeypointsOf>
class MonocularFeatureBuilder {
 public:
  // The initialisation budget: times the features while initialising (ORB-SLAM2's).
  static constexpr int kInitialisationBudget = 2;

  // Extractors for orb's budget and the initialisation budget.
  MonocularFeatureBuilder(KeypointsOf keypointsOf, const OrbParams& orb)
      : keypointsOf_(std::move(keypointsOf)), trackingExtractor_(orb), initialisationExtractor_(initialisationParams(orb)) {
    trackingExtractor_.setParallelLevels(true);  // one image per frame: its levels use both cores
    initialisationExtractor_.setParallelLevels(true);
  }
  // The frame's features.
  FrameFeatures build(const MonocularInput& in) {
    return keypointsOf_(isInitialising_ ? initialisationExtractor_ : trackingExtractor_, in.image);
  }
  // Switches the initialisation budget on or off (the tracker's owner does).
  void setInitialising(bool initialising) { isInitialising_ = initialising; }
  // Whether the builder uses the initialisation budget.
  bool initialising() const { return isInitialising_; }

 private:
  static OrbParams initialisationParams(OrbParams orb) {
    orb.features *= kInitialisationBudget;
    return orb;
  }
  KeypointsOf keypointsOf_;
  OrbExtractor trackingExtractor_, initialisationExtractor_;
  bool isInitialising_ = true;
};

// One camera, no depth: the map's scale is arbitrary (kMetricScale false), so the pipeline
// initialises from two views (geometry/two_view.hpp) rather than one frame, and loops are
// Sim(3). Keypoints are undistorted with the lens model (RadTan, zero = already undistorted).
//
// The initialisation budget (ORB-SLAM2: twice the features until the map exists, because the
// two-view initialiser needs many matches between frames far apart): the builder keeps a second
// extractor with twice the budget and uses it while initialising() is true. That state is set
// by whoever knows when the map exists (the tracker's owner calls setInitialising(false) after
// the two-view initialisation, true again after a reset), rather than "the first N frames":
// initialisation takes as many frames as the motion needs (a pure rotation never initialises),
// and a reset needs the larger budget again. A new builder starts initialising.
struct Monocular {
  // @{
  // The camera, its input and ORB-SLAM2's Huber kernel.
  using Camera = PinholeCamera<double>;
  using Input = MonocularInput;
  using RobustKernel = optim::HuberKernel;
  // @}
  // @{
  // No metric scale, no depth.
  static constexpr SensorKind kKind = SensorKind::Monocular;
  static constexpr bool kMetricScale = false;
  static constexpr bool kDepthFromSensor = false;
  // @}

  // Keypoints undistorted with a radial-tangential lens onto the camera's pinhole.
  struct UndistortedKeypoints {
    // @{
    // The pinhole and the images' distortion.
    Camera camera;
    RadTanDistortion<double> lens;
    // @}
    // The image's features.
    FrameFeatures operator()(OrbExtractor& extractor, const cv::Mat& image) const {
      return extractMonocular(extractor, image, camera, lens);
    }
  };

  // ORB on the image, keypoints undistorted with the lens; twice the budget while initialising.
  class FeatureBuilder : public MonocularFeatureBuilder<UndistortedKeypoints> {
   public:
    // lens: the images' distortion (zero when they are undistorted).
    FeatureBuilder(const Camera& camera, const OrbParams& orb, const RadTanDistortion<double>& lens = {})
        : MonocularFeatureBuilder<UndistortedKeypoints>({camera, lens}, orb) {}
  };
  // The initialisation budget: times the features while initialising.
  static constexpr int kInitialisationBudgetFactor = FeatureBuilder::kInitialisationBudget;
};

static_assert(SensorConfiguration<Monocular>);
static_assert(SensorConfiguration<Stereo>);
static_assert(SensorConfiguration<Rgbd>);

}  // namespace orbis
