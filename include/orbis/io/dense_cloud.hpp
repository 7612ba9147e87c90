// orbis/io/dense_cloud.hpp — a dense point cloud from RGB-D keyframes (paper Fig. 1b, 7).
//
// Contract: DenseCloudBuilder back-projects each depth map it is given, from the camera-to-world
// pose it is given, and averages the points (and colours) that fall into the same voxel. Depth is
// in metres (CV_32F) or raw (CV_16U, divided by depthScale); zero, NaN and readings beyond
// maxDepth are skipped. The result is ordered by voxel key, so the same inputs give the same
// file. Memory grows with the number of occupied voxels, not with the number of views.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/camera/pinhole.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

// How a dense cloud is sampled from depth maps.
struct DenseCloudOptions {
  double voxelSize = 0.01;  // metres
  double maxDepth = 4.0;    // metres: Kinect-type depth degrades quickly beyond
  int pixelStride = 2;      // every n-th pixel in both directions
};

// Back-projects depth maps into a coloured point cloud, one point per occupied voxel (orbis run
// --dense).
class DenseCloudBuilder {
 public:
  // camera: the depth maps' camera; depthScale: raw depth per metre.
  DenseCloudBuilder(const PinholeCamera<double>& camera, double depthScale, DenseCloudOptions options = {});

  // colour: 8-bit grey or BGR of the same size as depth, or empty.
  void addView(const SE3d& cameraToWorld, const cv::Mat& depth, const cv::Mat& colour);

  // Voxels occupied so far.
  std::size_t voxelCount() const { return voxels_.size(); }
  // The cloud: one point and colour per voxel.
  void points(std::vector<Eigen::Vector3f>& xyz, std::vector<std::array<std::uint8_t, 3>>& rgb) const;
  // Writes the cloud as binary PLY.
  void writePly(const std::filesystem::path& file) const;

 private:
  struct Voxel {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d colourSum = Eigen::Vector3d::Zero();
    std::uint32_t count = 0;
  };
  PinholeCamera<double> camera_;
  double depthScale_;
  DenseCloudOptions options_;
  std::map<std::int64_t, Voxel> voxels_;
};

}  // namespace orbis
