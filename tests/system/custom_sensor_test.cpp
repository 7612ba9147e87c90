// Sensor configurations the library does not ship, defined here, outside include/, and run end to
// end (tracking, local mapping, loop closing with full BA) on a rendered loop through the room
// without any library edit: the pipeline is instantiated from the headers for them.
//  - StereoWithCauchy: the shipped stereo rig and feature builder, with a Cauchy kernel in every
//    bundle adjustment (motion-only, local, full).
//  - DepthCameraWithTukey: a user's own pinhole-plus-depth camera model (its own projection and
//    Jacobian, no library camera type), its own feature builder and a Tukey kernel.
#include <gtest/gtest.h>

#include <iostream>

#include "orbis/eval/metrics.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/synth/sequence.hpp"
#include "orbis/system/slam.hpp"
#include "slam_test_util.hpp"

namespace {

using namespace orbis;

struct StereoWithCauchy {
  using Camera = RectifiedStereoCamera<double>;
  using Input = StereoInput;
  using RobustKernel = optim::CauchyKernel;
  static constexpr SensorKind kKind = SensorKind::Stereo;
  static constexpr bool kMetricScale = true;
  static constexpr bool kDepthFromSensor = false;
  using FeatureBuilder = Stereo::FeatureBuilder;
};

// A depth camera written from scratch: a pinhole that reports each point's depth as the
// disparity of a virtual baseline (the (uL, v, uR) observation every metric camera gives).
struct ToyDepthCamera {
  using Scalar = double;
  static constexpr int kObservationDim = 3;
  static constexpr bool kMetricDepth = true;

  PinholeCamera<double> pinhole;
  double baseline = 0.08;  // virtual, metres
  double closeDepth = 3.2;

  double bf() const { return pinhole.fx * baseline; }
  static bool inFront(const Eigen::Vector3d& pc) { return pc.z() > 1e-6; }
  Eigen::Vector3d project(const Eigen::Vector3d& pc) const {
    const double u = pinhole.fx * pc.x() / pc.z() + pinhole.cx;
    return {u, pinhole.fy * pc.y() / pc.z() + pinhole.cy, u - bf() / pc.z()};
  }
  Eigen::Matrix3d projectJacobian(const Eigen::Vector3d& pc) const {
    const double iz = 1.0 / pc.z(), iz2 = iz * iz;
    Eigen::Matrix3d J;
    J << pinhole.fx * iz, 0, -pinhole.fx * pc.x() * iz2,  //
        0, pinhole.fy * iz, -pinhole.fy * pc.y() * iz2,   //
        pinhole.fx * iz, 0, -pinhole.fx * pc.x() * iz2 + bf() * iz2;
    return J;
  }
  Eigen::Vector3d unproject(const Eigen::Vector2d& px, double depth) const { return pinhole.unproject(px, depth); }
  Eigen::Vector3d unproject(const Eigen::Vector3d& obs) const {
    return pinhole.unproject(obs.head<2>(), bf() / (obs.x() - obs.z()));
  }
  bool inImage(double u, double v) const { return pinhole.inImage(u, v); }
  double closeDepthThreshold() const { return closeDepth; }
};

struct DepthCameraWithTukey {
  using Camera = ToyDepthCamera;
  using Input = RgbdInput;
  using RobustKernel = optim::TukeyKernel;
  static constexpr SensorKind kKind = SensorKind::Rgbd;
  static constexpr bool kMetricScale = true;
  static constexpr bool kDepthFromSensor = true;

  class FeatureBuilder {
   public:
    FeatureBuilder(const Camera& camera, const OrbParams& orb)
        : depthCamera_(camera.pinhole, camera.baseline, 1.0, camera.closeDepth), extractor_(orb) {}
    FrameFeatures build(const Input& in) { return extractRgbd(extractor_, in.image, in.depth, depthCamera_); }

   private:
    RgbdCamera<double> depthCamera_;  // reads metric depth into (uL, v, uR) for the features
    OrbExtractor extractor_;
  };
};

static_assert(SensorConfiguration<StereoWithCauchy>);
static_assert(SensorConfiguration<DepthCameraWithTukey>);
static_assert(StereoCameraModel<ToyDepthCamera>);

using test::loopSequence;

struct CustomRun {
  SlamStats stats;
  std::size_t frames = 0;
  double ate = 0;
};

template <class Sensor>
CustomRun runCustom(const synth::SynthOptions& options, const typename Sensor::Camera& camera) {
  synth::SyntheticSequence seq(options);
  OrbParams orb;
  orb.features = 800;
  SlamOptions slamOptions;
  slamOptions.deterministic = true;
  slamOptions.fps = options.fps;
  slamOptions.seed = 11;
  Slam<Sensor> slam(camera, orb, test::sharedVocabulary(), slamOptions);
  Trajectory groundTruth;
  CustomRun run;
  run.frames = static_cast<std::size_t>(seq.size() + seq.size() / 4);
  for (std::size_t i = 0; i < run.frames; ++i) {
    const int k = static_cast<int>(i);
    synth::SynthFrame f = seq.render(k, !Sensor::kDepthFromSensor, Sensor::kDepthFromSensor);
    groundTruth.push_back({seq.timestamp(k), f.pose});
    if constexpr (Sensor::kDepthFromSensor) slam.track(RgbdInput{seq.timestamp(k), f.left, f.depth});
    else slam.track(StereoInput{seq.timestamp(k), f.left, f.right});
  }
  slam.shutdown();
  run.stats = slam.stats();
  run.ate = eval::computeAte(groundTruth, slam.trajectory(), {eval::Alignment::SE3, 0.001}).stats.rmse;
  return run;
}

// (Nearly) every frame tracked, the loop closed, and an error of the order the shipped sensors
// reach on these loops (tens of millimetres over a room-sized loop; LoopClosing.* measures those).
// Tukey gives residuals beyond its threshold no gradient at all, so a frame whose predicted pose
// starts far off can fail motion-only BA: measured 374 of 375 frames tracked with it (Cauchy 375).
void expectEndToEnd(const char* name, const CustomRun& run) {
  std::cout << "[custom sensor] " << name << ": tracked " << run.stats.tracked << "/" << run.frames << ", keyframes "
            << run.stats.keyFrames << ", loops " << run.stats.loopClosures << ", ATE " << run.ate * 1000 << " mm\n";
  EXPECT_GE(run.stats.tracked * 100, run.frames * 99);
  EXPECT_GE(run.stats.loopClosures, 1u);
  EXPECT_LT(run.ate, 0.08);
}

TEST(CustomSensor, StereoRigWithCauchyKernelRunsEndToEnd) {
  const auto options = loopSequence(22);
  synth::SyntheticSequence seq(options);
  const RectifiedStereoCamera<double> camera(seq.camera(), options.baseline);
  expectEndToEnd("stereo + Cauchy", runCustom<StereoWithCauchy>(options, camera));
}

TEST(CustomSensor, OwnDepthCameraWithTukeyKernelRunsEndToEnd) {
  const auto options = loopSequence(21);
  synth::SyntheticSequence seq(options);
  ToyDepthCamera camera;
  camera.pinhole = seq.camera();
  camera.closeDepth = 40 * camera.baseline;
  expectEndToEnd("own depth camera + Tukey", runCustom<DepthCameraWithTukey>(options, camera));
}

}  // namespace
