// Non-template steps of the FrameFeatures builders; see include/orbis/features/frame_features.hpp.
#include "orbis/features/frame_features.hpp"

#include <algorithm>
#include <cmath>

#include "orbis/util/error.hpp"

namespace orbis {

std::size_t FrameFeatures::stereoCount() const {
  return static_cast<std::size_t>(std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0.f; }));
}

namespace detail {

ImageBounds undistortedBounds(const PinholeCamera<double>& camera, const RadTanDistortion<double>& lens,
                              int width, int height) {
  const auto w = static_cast<double>(width), h = static_cast<double>(height);
  if (lens.isZero()) return {0.f, static_cast<float>(w), 0.f, static_cast<float>(h)};
  // The undistorted image corners, as ORB-SLAM: barrel distortion pushes them outwards.
  const Eigen::Vector2d c00 = undistortPixel(camera, lens, Eigen::Vector2d(0, 0));
  const Eigen::Vector2d c10 = undistortPixel(camera, lens, Eigen::Vector2d(w, 0));
  const Eigen::Vector2d c01 = undistortPixel(camera, lens, Eigen::Vector2d(0, h));
  const Eigen::Vector2d c11 = undistortPixel(camera, lens, Eigen::Vector2d(w, h));
  return {static_cast<float>(std::min(c00.x(), c01.x())), static_cast<float>(std::max(c10.x(), c11.x())),
          static_cast<float>(std::min(c00.y(), c10.y())), static_cast<float>(std::max(c01.y(), c11.y()))};
}

void finishMonocular(FrameFeatures& f, const PinholeCamera<double>& camera,
                     const RadTanDistortion<double>& lens, int width, int height) {
  f.keypointsUn = undistortPoints(f.keypoints, camera, lens);
  f.uRight.assign(f.keypoints.size(), -1.f);
  f.depth.assign(f.keypoints.size(), -1.f);
  const ImageBounds b = undistortedBounds(camera, lens, width, height);
  f.grid.build(f.keypointsUn, b.minX, b.maxX, b.minY, b.maxY);
}

void assignDepth(FrameFeatures& f, const cv::Mat& depthImage, double depthScale, double bf) {
  if (depthImage.type() != CV_16UC1 && depthImage.type() != CV_32FC1)
    throw Error("depth image", "", "expected CV_16UC1 or CV_32FC1, got OpenCV type " +
                                       std::to_string(depthImage.type()));
  if (depthImage.empty()) return;
  const bool raw16 = depthImage.type() == CV_16UC1;
  const double toMetres = 1.0 / depthScale;
  for (std::size_t i = 0; i < f.keypoints.size(); ++i) {
    // Depth is registered to the raw (distorted) colour image, so read it at the raw position.
    const int u = static_cast<int>(std::lround(f.keypoints[i].u));
    const int v = static_cast<int>(std::lround(f.keypoints[i].v));
    if (u < 0 || v < 0 || u >= depthImage.cols || v >= depthImage.rows) continue;
    const double raw = raw16 ? static_cast<double>(depthImage.at<std::uint16_t>(v, u))
                             : static_cast<double>(depthImage.at<float>(v, u));
    const double d = raw * toMetres;
    if (!(d > 0.0) || !std::isfinite(d)) continue;  // 0, negative and NaN: no measurement
    f.depth[i] = static_cast<float>(d);
    f.uRight[i] = static_cast<float>(f.keypointsUn[i].u - bf / d);
  }
}

}  // namespace detail
}  // namespace orbis
