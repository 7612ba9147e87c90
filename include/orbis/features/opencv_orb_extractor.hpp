// orbis/features/opencv_orb_extractor.hpp — OpenCV's cv::ORB behind the FeatureExtractor
// concept, for comparison and for users who prefer it.
//
// Contract: same budget, levels, scale factor and (high) FAST threshold as OrbExtractor, Harris
// ranking, patch size 31; OpenCV picks the strongest corners per level, so keypoints cluster
// on texture instead of covering the image. pyramid() is built with ImagePyramid (OpenCV does
// not expose its own) so stereo matching works with either extractor. Not thread-safe.
#pragma once

#include <span>
#include <vector>

#include <opencv2/features2d.hpp>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/extractor.hpp"
#include "orbis/features/image_pyramid.hpp"
#include "orbis/features/keypoint.hpp"
#include "orbis/features/orb_params.hpp"

namespace orbis {

// cv::ORB behind the FeatureExtractor interface: a reference to measure OrbExtractor against.
class OpenCvOrbExtractor : public PyramidExtractorBase {
 public:
  // An extractor with ORB-SLAM's parameters.
  explicit OpenCvOrbExtractor(const OrbParams& params = {});

  // Keypoints and descriptors of an 8-bit image.
  void extract(const cv::Mat& image, std::vector<Keypoint>& keypoints,
               std::vector<OrbDescriptor>& descriptors);


 private:
  cv::Ptr<cv::ORB> orb_;
  cv::Mat gray_, cvDescriptors_;
  std::vector<cv::KeyPoint> cvKeypoints_;
};

static_assert(FeatureExtractor<OpenCvOrbExtractor>);

}  // namespace orbis
