// The Monocular sensor configuration: it meets SensorConfiguration, extracts with twice the
// budget while initialising and the normal budget afterwards, undistorts keypoints with its
// lens, and gives no keypoint a depth.
#include <gtest/gtest.h>

#include "features/feature_test_util.hpp"
#include "orbis/sensor/sensor.hpp"

namespace orbis {
namespace {

static_assert(SensorConfiguration<Monocular>);
static_assert(!Monocular::kMetricScale && !Monocular::kDepthFromSensor);

const PinholeCamera<double> kCamera{520, 520, 320, 240, 640, 480};

TEST(MonocularSensor, DoubleBudgetWhileInitialising) {
  OrbParams orb;
  orb.features = 500;
  Monocular::FeatureBuilder builder(kCamera, orb);
  // Small shapes: far more corners than either budget keeps.
  const MonocularInput input{0.0, test::texturedImage(640, 480, 5, 150)};
  ASSERT_TRUE(builder.initialising());
  const FrameFeatures initialising = builder.build(input);
  builder.setInitialising(false);
  const FrameFeatures tracking = builder.build(input);
  std::printf("  keypoints: %zu initialising, %zu tracking (budget %d)\n", initialising.size(), tracking.size(),
              orb.features);
  EXPECT_GT(initialising.size(), std::size_t(1.6 * orb.features));
  EXPECT_LE(initialising.size(), std::size_t(1.1 * 2 * orb.features));
  EXPECT_LE(tracking.size(), std::size_t(1.1 * orb.features));
  EXPECT_GT(tracking.size(), std::size_t(0.8 * orb.features));
  builder.setInitialising(true);  // after a reset: the larger budget again
  EXPECT_EQ(builder.build(input).size(), initialising.size());
  for (std::size_t i = 0; i < tracking.size(); ++i) EXPECT_EQ(tracking.kind(i), KeypointKind::Monocular);
}

TEST(MonocularSensor, KeypointsAreUndistortedWithTheLens) {
  const MonocularInput input{0.0, test::texturedImage(640, 480, 6)};
  Monocular::FeatureBuilder ideal(kCamera, OrbParams{});
  const FrameFeatures straight = ideal.build(input);
  ASSERT_GT(straight.size(), 100u);
  for (std::size_t i = 0; i < straight.size(); ++i) {
    EXPECT_EQ(straight.keypointsUn[i].u, straight.keypoints[i].u);
    EXPECT_EQ(straight.keypointsUn[i].v, straight.keypoints[i].v);
  }
  const RadTanDistortion<double> barrel{-0.28, 0.07, 0, 0, 0};
  Monocular::FeatureBuilder withLens(kCamera, OrbParams{}, barrel);
  const FrameFeatures bent = withLens.build(input);
  ASSERT_EQ(bent.size(), straight.size());
  double largestShift = 0;
  for (std::size_t i = 0; i < bent.size(); ++i) {
    const Eigen::Vector2d distorted(bent.keypoints[i].u, bent.keypoints[i].v);
    const Eigen::Vector2d ideal(bent.keypointsUn[i].u, bent.keypointsUn[i].v);
    // Distorting the undistorted keypoint gives the detected one back.
    const Eigen::Vector2d back = kCamera.normalizedToPixel(barrel.distort(kCamera.pixelToNormalized(ideal)));
    EXPECT_LT((back - distorted).norm(), 1e-2);
    largestShift = std::max(largestShift, (ideal - distorted).norm());
  }
  EXPECT_GT(largestShift, 10.0);  // barrel distortion moves the corners by tens of pixels
}

}  // namespace
}  // namespace orbis
