#include "orbis/io/dense_cloud.hpp"

#include <cmath>

#include "orbis/io/ply.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace {

// 21 bits per axis: ±10 km at 1 cm voxels.
constexpr std::int64_t kAxisBits = 21;
constexpr std::int64_t kAxisOffset = std::int64_t(1) << (kAxisBits - 1);
constexpr std::int64_t kAxisMask = (std::int64_t(1) << kAxisBits) - 1;

bool voxelKey(const Eigen::Vector3d& p, double voxel, std::int64_t& key) {
  std::int64_t c[3];
  for (int a = 0; a < 3; ++a) {
    const double v = std::floor(p[a] / voxel);
    if (!(std::abs(v) < static_cast<double>(kAxisOffset))) return false;
    c[a] = static_cast<std::int64_t>(v) + kAxisOffset;
  }
  key = (c[0] << (2 * kAxisBits)) | (c[1] << kAxisBits) | c[2];
  return (c[0] & ~kAxisMask) == 0;
}

}  // namespace

DenseCloudBuilder::DenseCloudBuilder(const PinholeCamera<double>& camera, double depthScale, DenseCloudOptions options)
    : camera_(camera), depthScale_(depthScale), options_(options) {
  if (!(options_.voxelSize > 0)) throw Error("dense cloud", "voxelSize", "must be positive");
  if (options_.pixelStride < 1) options_.pixelStride = 1;
}

void DenseCloudBuilder::addView(const SE3d& cameraToWorld, const cv::Mat& depth, const cv::Mat& colour) {
  if (depth.empty()) return;
  if (depth.type() != CV_32F && depth.type() != CV_16U)
    throw Error("dense cloud", "depth", "expected a CV_32F (metres) or CV_16U (raw) depth map");
  const bool haveColour = !colour.empty() && colour.size() == depth.size() &&
                          (colour.type() == CV_8UC1 || colour.type() == CV_8UC3);
  const double rawToMetres = depth.type() == CV_16U ? 1.0 / depthScale_ : 1.0;
  const Eigen::Matrix3d R = cameraToWorld.rotationMatrix();
  const Eigen::Vector3d t = cameraToWorld.translation();
  for (int v = 0; v < depth.rows; v += options_.pixelStride) {
    for (int u = 0; u < depth.cols; u += options_.pixelStride) {
      const double z = rawToMetres * (depth.type() == CV_16U ? double(depth.at<std::uint16_t>(v, u))
                                                             : double(depth.at<float>(v, u)));
      if (!(z > 0) || !(z <= options_.maxDepth)) continue;  // also rejects NaN
      const Eigen::Vector3d pc = camera_.unproject(Eigen::Vector2d(u, v), z);
      const Eigen::Vector3d pw = R * pc + t;
      std::int64_t key;
      if (!voxelKey(pw, options_.voxelSize, key)) continue;
      Voxel& voxel = voxels_[key];
      voxel.sum += pw;
      if (haveColour) {
        if (colour.type() == CV_8UC3) {
          const cv::Vec3b bgr = colour.at<cv::Vec3b>(v, u);
          voxel.colourSum += Eigen::Vector3d(bgr[2], bgr[1], bgr[0]);
        } else {
          voxel.colourSum += Eigen::Vector3d::Constant(colour.at<std::uint8_t>(v, u));
        }
      } else {
        voxel.colourSum += Eigen::Vector3d::Constant(200);
      }
      ++voxel.count;
    }
  }
}

void DenseCloudBuilder::points(std::vector<Eigen::Vector3f>& xyz, std::vector<std::array<std::uint8_t, 3>>& rgb) const {
  xyz.clear();
  rgb.clear();
  xyz.reserve(voxels_.size());
  rgb.reserve(voxels_.size());
  for (const auto& [key, voxel] : voxels_) {
    const double n = voxel.count;
    xyz.push_back((voxel.sum / n).cast<float>());
    const Eigen::Vector3d c = (voxel.colourSum / n).array().round().min(255.0).max(0.0);
    rgb.push_back({static_cast<std::uint8_t>(c[0]), static_cast<std::uint8_t>(c[1]), static_cast<std::uint8_t>(c[2])});
  }
}

void DenseCloudBuilder::writePly(const std::filesystem::path& file) const {
  std::vector<Eigen::Vector3f> xyz;
  std::vector<std::array<std::uint8_t, 3>> rgb;
  points(xyz, rgb);
  orbis::writePly(file, xyz, rgb);
}

}  // namespace orbis
