// The MonocularFisheye sensor: ORB on the fisheye image, each keypoint's ray put on the lens's
// tangent plane exactly; rays past the keypoint angle dropped; the grid spans the plane's image.
#include <gtest/gtest.h>

#include <cmath>

#include "orbis/sensor/monocular_fisheye.hpp"
#include "orbis/synth/sequence.hpp"

namespace orbis {
namespace {

static_assert(SensorConfiguration<MonocularFisheye>);
static_assert(std::same_as<PipelineSensor<MonocularFisheye>, Monocular>);
static_assert(std::same_as<PipelineSensor<Stereo>, Stereo>);

TEST(MonocularFisheyeSensor, KeypointsOnTheTangentPlane) {
  synth::SynthOptions o;
  o.width = 640;
  o.height = 480;
  o.fisheye = true;
  o.fisheyeFovDegrees = 180;
  synth::SyntheticSequence sequence(o);
  const KannalaBrandtCamera<double> lens = sequence.fisheyeCamera();
  const MonocularInput input{0.0, sequence.render(10, false, false).left};
  MonocularFisheye::FeatureBuilder builder(MonocularFisheye::planeOf(lens), OrbParams{}, lens, 70.0);
  const FrameFeatures f = builder.build(input);
  ASSERT_GT(f.size(), 300u);
  ASSERT_EQ(f.keypointsUn.size(), f.size());
  ASSERT_EQ(f.descriptors.size(), f.size());
  const PinholeCamera<double> plane = MonocularFisheye::planeOf(lens);
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
  MonocularFisheye::FeatureBuilder narrow(plane, OrbParams{}, lens, 45.0);
  EXPECT_LT(narrow.build(input).size(), f.size());
}

}  // namespace
}  // namespace orbis
