// orbis/features/fisheye_features.hpp — frame features of a fisheye image on its lens's tangent
// plane.
//
// Contract: extractFisheye() runs the extractor on the fisheye image as the lens took it, then
// puts each keypoint's ray (KannalaBrandtCamera::bearing, exact) on the lens's tangent plane:
// keypointsUn[i] is the pixel of that ray through lens.centralPinhole(), the pinhole with the
// lens's fx, fy, cx, cy. Keypoints further than maxAngle off axis (radians, under 90°, where the
// plane ends and a pixel's error is stretched by 1/cos²θ) are dropped with their descriptors.
// The grid spans where the image's rays up to maxAngle land on the plane. No keypoint has depth.
#pragma once

#include <opencv2/core.hpp>

#include "orbis/camera/kannala_brandt.hpp"
#include "orbis/features/frame_features.hpp"

namespace orbis {

namespace detail {
void finishFisheye(FrameFeatures& f, const KannalaBrandtCamera<double>& lens, double maxAngle, int width, int height);
}  // namespace detail

template <FeatureExtractor E>
FrameFeatures extractFisheye(E& extractor, const cv::Mat& image, const KannalaBrandtCamera<double>& lens,
                             double maxAngle) {
  FrameFeatures f;
  extractor.extract(image, f.keypoints, f.descriptors);
  f.scales = extractor.scaleLevels();
  detail::finishFisheye(f, lens, maxAngle, image.cols, image.rows);
  return f;
}

}  // namespace orbis
