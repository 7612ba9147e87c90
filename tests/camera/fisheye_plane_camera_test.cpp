// FisheyePlaneCamera: the tangent plane's geometry, the lens's pixels for the noise. A plane
// observation maps back to the fisheye pixel of the same ray; the window stretch is the plane's
// radial displacement per fisheye pixel (checked against finite differences up to 85 degrees);
// cameras without a lens are never stretched.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "orbis/camera/fisheye_plane_camera.hpp"

namespace orbis {
namespace {

KannalaBrandtCamera<double> lens180() {
  KannalaBrandtCamera<double> lens;
  lens.fx = lens.fy = 199.722;
  lens.cx = 320, lens.cy = 240;
  lens.k1 = 0.01, lens.k2 = -0.002, lens.k3 = 0.0005, lens.k4 = 0;
  lens.width = 640, lens.height = 480;
  return lens;
}

Eigen::Vector3d rayAt(double thetaDegrees, double azimuthDegrees) {
  const double t = thetaDegrees * std::numbers::pi / 180, a = azimuthDegrees * std::numbers::pi / 180;
  return {std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)};
}

TEST(FisheyePlaneCamera, PlaneObservationsMapBackToTheirFisheyePixel) {
  const auto camera = FisheyePlaneCamera<double>::ofLens(lens180());
  EXPECT_EQ(camera.pinhole.fx, camera.lens.fx);
  EXPECT_EQ(camera.pinhole.cx, camera.lens.cx);
  double worst = 0;
  for (double theta = 0; theta <= 85; theta += 5) {
    for (double azimuth = 0; azimuth < 360; azimuth += 37) {
      const Eigen::Vector3d pc = 3.0 * rayAt(theta, azimuth);
      const Eigen::Vector2d onPlane = camera.project(pc);
      worst = std::max(worst, (camera.lensPixel(onPlane) - camera.lens.project(pc)).norm());
    }
  }
  std::printf("  plane -> lens pixel round trip: worst %.2e px up to 85 degrees\n", worst);
  EXPECT_LT(worst, 1e-8);
}

TEST(FisheyePlaneCamera, WindowStretchIsThePlanesRadialDisplacementPerLensPixel) {
  const auto camera = FisheyePlaneCamera<double>::ofLens(lens180());
  EXPECT_NEAR(camera.windowStretch(Eigen::Vector3d(0, 0, 2)), 1.0, 1e-12);
  for (double theta : {10.0, 30.0, 54.0, 70.0, 80.0, 85.0}) {
    const Eigen::Vector3d pc = rayAt(theta, 30);
    const Eigen::Vector2d px = camera.lens.project(pc);
    const Eigen::Vector2d radial = (px - Eigen::Vector2d(camera.lens.cx, camera.lens.cy)).normalized();
    const Eigen::Vector2d tangential(-radial.y(), radial.x());
    const double h = 1e-4;
    const auto planeOf = [&](const Eigen::Vector2d& lensPx) { return camera.pinhole.project(camera.lens.bearing(lensPx)); };
    const double radialStretch = (planeOf(px + h * radial) - planeOf(px - h * radial)).norm() / (2 * h);
    const double tangentialStretch = (planeOf(px + h * tangential) - planeOf(px - h * tangential)).norm() / (2 * h);
    std::printf("  %4.0f deg: stretch %.3f radially (analytic %.3f), %.3f tangentially\n", theta, radialStretch,
                camera.windowStretch(pc), tangentialStretch);
    EXPECT_NEAR(camera.windowStretch(pc), radialStretch, 1e-5 * radialStretch);
    EXPECT_LE(tangentialStretch, camera.windowStretch(pc) * (1 + 1e-6));
  }
  // The equidistant lens at 70 degrees: 1 / (cos² θ θd'(θ)), about 8.5 for this polynomial.
  EXPECT_GT(camera.windowStretch(rayAt(70, 0)), 8.0);
  EXPECT_TRUE(std::isinf(camera.windowStretch(rayAt(95, 0))));
}

TEST(FisheyePlaneCamera, OnlyLensCamerasStretchWindows) {
  const auto camera = FisheyePlaneCamera<double>::ofLens(lens180());
  const PinholeCamera<double> pinhole{500, 500, 320, 240, 640, 480};
  const Eigen::Vector3d pc = rayAt(60, 0);
  EXPECT_EQ(searchWindowStretch(pinhole, pc), 1.f);
  EXPECT_NEAR(searchWindowStretch(camera, pc), camera.windowStretch(pc), 1e-5);
  // Capped where the plane runs off to infinity.
  EXPECT_LE(searchWindowStretch(camera, rayAt(89.99, 0)), 1e3f);
}

}  // namespace
}  // namespace orbis
