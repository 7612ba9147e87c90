// orbis/features/frame_features.hpp — everything the tracker keeps of an input frame (paper
// Fig. 2b): keypoints, descriptors, stereo coordinate, depth, and a grid for area queries.
//
// Contract: per keypoint i (all arrays the same length): keypoints[i] as detected (raw image),
// keypointsUn[i] undistorted (equal to keypoints[i] for rectified or undistorted input),
// descriptors[i], uRight[i] (right-image column of a stereo keypoint, or the virtual one
// u - bf/d for RGB-D; -1 for a monocular keypoint) and depth[i] (metres, -1 when unknown).
// kind(i) is Monocular without depth, Close when depth < closeDepth (camera's threshold, 40
// baselines by default), else Far. The grid indexes keypointsUn over the undistorted image
// bounds (the undistorted image corners for a distorting lens, the image rectangle otherwise).
// Builders: extractMonocular, extractStereo (rectified pair extracted on two threads: the
// extractor's extractPair when it has one, else the right image on a second thread), extractRgbd (depth image CV_16U or CV_32F, raw value / depthScale =
// metres; 0, negative or NaN means no depth). Errors of input type throw orbis::Error.
#pragma once

#include <future>
#include <limits>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "orbis/camera/distortion.hpp"
#include "orbis/camera/pinhole.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/features/descriptor.hpp"
#include "orbis/features/extractor.hpp"
#include "orbis/features/feature_grid.hpp"
#include "orbis/features/keypoint.hpp"
#include "orbis/features/stereo_matcher.hpp"

namespace orbis {

// How a keypoint enters the map and BA: no depth, close stereo/depth, or far (beyond ThDepth).
enum class KeypointKind { Monocular, Close, Far };

// One frame's features: keypoints, descriptors, stereo coordinates, depths and an area index.
struct FrameFeatures {
  // Keypoints as detected.
  std::vector<Keypoint> keypoints;
  // The same, undistorted.
  std::vector<Keypoint> keypointsUn;
  // One descriptor per keypoint.
  std::vector<OrbDescriptor> descriptors;
  // Right-image coordinate per keypoint, or −1 when it has no stereo partner or depth.
  std::vector<float> uRight;
  // Depth per keypoint (metres), or −1.
  std::vector<float> depth;
  // Depth below which a keypoint is close.
  float closeDepth = std::numeric_limits<float>::infinity();
  // The pyramid's scales.
  ScaleLevels scales;
  // Area index over the undistorted keypoints.
  FeatureGrid grid;

  // Number of keypoints.
  std::size_t size() const { return keypoints.size(); }
  // Whether keypoint i has a depth.
  bool hasDepth(std::size_t i) const { return depth[i] > 0.f; }
  // Monocular, close or far.
  KeypointKind kind(std::size_t i) const {
    if (!hasDepth(i)) return KeypointKind::Monocular;
    return depth[i] < closeDepth ? KeypointKind::Close : KeypointKind::Far;
  }
  // Keypoints with a stereo partner or depth.
  std::size_t stereoCount() const;
};

// Image-bound helpers and the non-template steps of the builders (frame_features.cpp).
namespace detail {
struct ImageBounds {
  float minX, maxX, minY, maxY;
};
ImageBounds undistortedBounds(const PinholeCamera<double>& camera, const RadTanDistortion<double>& lens,
                              int width, int height);
void finishMonocular(FrameFeatures& f, const PinholeCamera<double>& camera,
                     const RadTanDistortion<double>& lens, int width, int height);
void assignDepth(FrameFeatures& f, const cv::Mat& depthImage, double depthScale, double bf);
}  // namespace detail

// Features of a monocular image: keypoints undistorted with the lens, no depth.
template <FeatureExtractor E>
FrameFeatures extractMonocular(E& extractor, const cv::Mat& image, const PinholeCamera<double>& camera,
                               const RadTanDistortion<double>& lens = {}) {
  FrameFeatures f;
  extractor.extract(image, f.keypoints, f.descriptors);
  f.scales = extractor.scaleLevels();
  detail::finishMonocular(f, camera, lens, image.cols, image.rows);
  return f;
}

// `matcher` carries reusable buffers; pass the same one every frame. The right extractor may
// have a larger budget than the left: the quadtree keeps different corners in the two views,
// so more right keypoints give more left keypoints a partner (on the synthetic room sequence
// 55% of left keypoints match with equal budgets, 71% with three times the budget on the right).
template <FeatureExtractor E>
FrameFeatures extractStereo(E& leftExtractor, E& rightExtractor, const cv::Mat& leftImage,
                            const cv::Mat& rightImage, const RectifiedStereoCamera<double>& camera,
                            StereoMatcher& matcher) {
  FrameFeatures f;
  std::vector<Keypoint> rightKeypoints;
  std::vector<OrbDescriptor> rightDescriptors;
  if constexpr (requires {
                  E::extractPair(leftExtractor, leftImage, f.keypoints, f.descriptors, rightExtractor, rightImage,
                                 rightKeypoints, rightDescriptors);
                }) {
    // Both images' levels shared by two threads as they come free (OrbExtractor::extractPair).
    E::extractPair(leftExtractor, leftImage, f.keypoints, f.descriptors, rightExtractor, rightImage, rightKeypoints,
                   rightDescriptors);
  } else {
    // The right image on a thread of its own, the left on the caller's. std::async rather than
    // cv::parallel_for_: OpenCV's pool synchronises in uninstrumented code, which ThreadSanitizer
    // cannot see, and one extra thread per frame costs tens of microseconds against milliseconds.
    auto right = std::async(std::launch::async,
                            [&] { rightExtractor.extract(rightImage, rightKeypoints, rightDescriptors); });
    leftExtractor.extract(leftImage, f.keypoints, f.descriptors);
    right.get();
  }
  f.scales = leftExtractor.scaleLevels();
  f.closeDepth = static_cast<float>(camera.closeDepthThreshold());
  detail::finishMonocular(f, camera.pinhole, {}, leftImage.cols, leftImage.rows);
  matcher.match({f.keypoints, f.descriptors, leftExtractor.pyramid()},
                {rightKeypoints, rightDescriptors, rightExtractor.pyramid()}, f.scales,
                static_cast<float>(camera.bf()), static_cast<float>(camera.baseline), f.uRight, f.depth);
  return f;
}

// Features of an RGB-D frame: keypoints on the colour image, depth read at each.
template <FeatureExtractor E>
FrameFeatures extractRgbd(E& extractor, const cv::Mat& image, const cv::Mat& depthImage,
                          const RgbdCamera<double>& camera, const RadTanDistortion<double>& lens = {}) {
  FrameFeatures f;
  extractor.extract(image, f.keypoints, f.descriptors);
  f.scales = extractor.scaleLevels();
  f.closeDepth = static_cast<float>(camera.closeDepthThreshold());
  detail::finishMonocular(f, camera.pinhole, lens, image.cols, image.rows);
  detail::assignDepth(f, depthImage, camera.depthScale, camera.bf());
  return f;
}

}  // namespace orbis
