// The fisheye renderer against the pinhole one: a fisheye frame remapped through the
// Kannala-Brandt model onto a pinhole of the same pose must show what the pinhole renders, and
// its depth must be the z of the scene point its pixel sees.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "orbis/synth/sequence.hpp"

namespace orbis::synth {
namespace {

SynthOptions smallOptions(bool fisheye) {
  SynthOptions o;
  o.width = 320;
  o.height = 240;
  o.fx = 160;
  o.frames = 100;
  o.fisheye = fisheye;
  o.fisheyeFovDegrees = 180;
  return o;
}

TEST(FisheyeRender, RemappedToPinholeMatchesThePinholeRender) {
  SyntheticSequence pinholeSeq(smallOptions(false)), fisheyeSeq(smallOptions(true));
  const PinholeCamera<double> pinhole = pinholeSeq.camera();
  const KannalaBrandtCamera<double> lens = fisheyeSeq.fisheyeCamera();
  EXPECT_NEAR(lens.horizontalFieldOfViewDegrees(), 180.0, 1e-6);
  for (int i : {0, 40}) {
    const SynthFrame p = pinholeSeq.render(i, false, false);
    const SynthFrame f = fisheyeSeq.render(i, false, true);
    cv::Mat mapX(pinhole.height, pinhole.width, CV_32FC1), mapY(pinhole.height, pinhole.width, CV_32FC1);
    for (int y = 0; y < pinhole.height; ++y)
      for (int x = 0; x < pinhole.width; ++x) {
        const Eigen::Vector2d px = lens.project(pinhole.normalizedRay(Eigen::Vector2d(x, y)));
        mapX.at<float>(y, x) = static_cast<float>(px.x());
        mapY.at<float>(y, x) = static_cast<float>(px.y());
      }
    cv::Mat remapped, a, b;
    cv::remap(f.left, remapped, mapX, mapY, cv::INTER_LINEAR);
    remapped.convertTo(a, CV_32F);
    p.left.convertTo(b, CV_32F);
    // The fisheye samples the centre of the view at about the pinhole's resolution (fx 102 vs
    // 160), so fine texture differs; structure must agree.
    cv::GaussianBlur(a, a, cv::Size(7, 7), 2.0);
    cv::GaussianBlur(b, b, cv::Size(7, 7), 2.0);
    const cv::Scalar meanA = cv::mean(a), meanB = cv::mean(b);
    cv::Mat da = a - meanA[0], db = b - meanB[0];
    const double ncc = da.dot(db) / std::sqrt(da.dot(da) * db.dot(db));
    std::printf("  frame %d: NCC of the remapped fisheye against the pinhole %.3f\n", i, ncc);
    EXPECT_GT(ncc, 0.85);
    // Depth: z of the scene point the pixel's ray hits, behind the image plane included.
    int checked = 0, behind = 0;
    for (int y = 5; y < f.depth.rows; y += 23)
      for (int x = 3; x < f.depth.cols; x += 29) {
        const float z = f.depth.at<float>(y, x);
        if (z == 0.f) continue;
        const Eigen::Vector3d ray = lens.bearing(Eigen::Vector2d(x, y));
        const auto hit = fisheyeSeq.scene().intersect(f.pose.translation(), f.pose.rotationMatrix() * ray);
        ASSERT_TRUE(hit.has_value());
        EXPECT_NEAR(z, hit->distance * ray.z(), 1e-3 * std::abs(hit->distance));
        ++checked;
        behind += z < 0;
      }
    EXPECT_GT(checked, 50);
    EXPECT_GT(behind, 0);  // the corners of a 180-degree view look behind the image plane
  }
}

}  // namespace
}  // namespace orbis::synth
