// DenseCloudBuilder: back-projection from a known pose, voxel averaging, invalid depth skipped.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "orbis/io/dense_cloud.hpp"

namespace {

using namespace orbis;

PinholeCamera<double> camera() {
  PinholeCamera<double> c;
  c.fx = c.fy = 100;
  c.cx = 20;
  c.cy = 15;
  c.width = 40;
  c.height = 30;
  return c;
}

TEST(DenseCloud, FlatWallLandsWhereThePoseSaysAndInvalidDepthIsSkipped) {
  cv::Mat depth(30, 40, CV_32F, cv::Scalar(2.0f));
  depth.at<float>(0, 0) = 0;
  depth.at<float>(0, 2) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(2, 0) = 50;  // beyond maxDepth
  const SE3d cameraToWorld(SO3d::exp(Eigen::Vector3d(0, 0.3, 0)), Eigen::Vector3d(1, 2, 3));
  DenseCloudOptions options;
  options.voxelSize = 1e-4;  // finer than the pixel footprint: one point per pixel used
  options.pixelStride = 2;
  DenseCloudBuilder builder(camera(), 1.0, options);
  builder.addView(cameraToWorld, depth, {});
  std::vector<Eigen::Vector3f> xyz;
  std::vector<std::array<std::uint8_t, 3>> rgb;
  builder.points(xyz, rgb);
  EXPECT_EQ(xyz.size(), std::size_t(15 * 20 - 3));
  ASSERT_EQ(rgb.size(), xyz.size());
  const SE3d worldToCamera = cameraToWorld.inverse();
  for (const auto& p : xyz) {
    const Eigen::Vector3d pc = worldToCamera * p.cast<double>();
    EXPECT_NEAR(pc.z(), 2.0, 2e-4);  // on the wall, up to the voxel averaging
  }
}

TEST(DenseCloud, VoxelsAverageRepeatedViewsAndRawDepthIsScaled) {
  cv::Mat raw(30, 40, CV_16U, cv::Scalar(5000));  // 1 m at factor 5000
  cv::Mat grey(30, 40, CV_8UC1, cv::Scalar(90));
  DenseCloudOptions options;
  options.voxelSize = 0.05;
  options.pixelStride = 1;
  DenseCloudBuilder builder(camera(), 5000, options);
  builder.addView(SE3d(), raw, grey);
  const std::size_t once = builder.voxelCount();
  builder.addView(SE3d(), raw, grey);  // the same view again adds no voxel
  EXPECT_EQ(builder.voxelCount(), once);
  // The wall spans 0.4 x 0.3 m at 1 m: about 8 x 6 voxels of 5 cm (cell boundaries add a row or column).
  EXPECT_GE(once, 48u);
  EXPECT_LE(once, 63u);
  std::vector<Eigen::Vector3f> xyz;
  std::vector<std::array<std::uint8_t, 3>> rgb;
  builder.points(xyz, rgb);
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    EXPECT_NEAR(xyz[i].z(), 1.0, 1e-5);
    EXPECT_EQ(rgb[i][0], 90);
  }
}

TEST(DenseCloud, WrongDepthTypeIsAnError) {
  DenseCloudBuilder builder(camera(), 1.0);
  EXPECT_THROW(builder.addView(SE3d(), cv::Mat(30, 40, CV_8UC1, cv::Scalar(1)), {}), Error);
}

}  // namespace
