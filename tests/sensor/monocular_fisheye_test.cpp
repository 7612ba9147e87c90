// The MonocularFisheye sensor: ORB on the fisheye image, each keypoint's ray put on the lens's
// tangent plane exactly; rays past the keypoint angle dropped; the grid spans the plane's image.
#include <gtest/gtest.h>

#include <cmath>

#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/synth/sequence.hpp"

namespace orbis {
namespace {

static_assert(SensorConfiguration<MonocularFisheye>);
static_assert(ObservesThroughLens<MonocularFisheye::Camera> && !ObservesThroughLens<Monocular::Camera>);

TEST(MonocularFisheyeSensor, KeypointsOnTheTangentPlane) {
  synth::SynthOptions o;
  o.width = 640;
  o.height = 480;
  o.fisheye = true;
  o.fisheyeFovDegrees = 180;
  synth::SyntheticSequence sequence(o);
  const KannalaBrandtCamera<double> lens = sequence.fisheyeCamera();
  const MonocularInput input{0.0, sequence.render(10, false, false).left};
  const MonocularFisheye::Camera camera = MonocularFisheye::cameraOf(lens);
  MonocularFisheye::FeatureBuilder builder(camera, OrbParams{}, 70.0);
  const FrameFeatures f = builder.build(input);
  ASSERT_GT(f.size(), 300u);
  ASSERT_EQ(f.keypointsUn.size(), f.size());
  ASSERT_EQ(f.descriptors.size(), f.size());
  const PinholeCamera<double>& plane = camera.pinhole;
  double widest = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const Eigen::Vector3d ray = lens.bearing(Eigen::Vector2d(f.keypoints[i].u, f.keypoints[i].v));
    const double angle = std::acos(ray.z()) * 180 / M_PI;
    widest = std::max(widest, angle);
    EXPECT_LE(angle, 70.0 + 1e-6);
    const Eigen::Vector2d onPlane = plane.project(ray);
    EXPECT_NEAR(f.keypointsUn[i].u, onPlane.x(), 1e-2 * std::max(1.0, std::abs(onPlane.x()) / 100));
    EXPECT_NEAR(f.keypointsUn[i].v, onPlane.y(), 1e-2 * std::max(1.0, std::abs(onPlane.y()) / 100));
    EXPECT_TRUE(f.grid.inBounds(f.keypointsUn[i].u, f.keypointsUn[i].v));
    EXPECT_EQ(f.kind(i), KeypointKind::Monocular);
  }
  std::printf("  %zu keypoints kept, the widest %.1f degrees off axis; grid %.0f..%.0f x %.0f..%.0f\n", f.size(),
              widest, f.grid.minX(), f.grid.maxX(), f.grid.minY(), f.grid.maxY());
  EXPECT_GT(widest, 55.0);  // the periphery is used, not only a pinhole-sized centre
  // A narrower cut keeps fewer.
  MonocularFisheye::FeatureBuilder narrow(camera, OrbParams{}, 45.0);
  EXPECT_LT(narrow.build(input).size(), f.size());
  // The default reaches further out, and the builder keeps Monocular's initialisation budget.
  MonocularFisheye::FeatureBuilder wide(camera, OrbParams{});
  EXPECT_TRUE(wide.initialising());
  const std::size_t initialising = wide.build(input).size();
  wide.setInitialising(false);
  const std::size_t tracking = wide.build(input).size();
  EXPECT_GT(initialising, f.size());  // both with the initialisation budget, 80 against 70 degrees
  EXPECT_GT(initialising, tracking);
}

}  // namespace
}  // namespace orbis
