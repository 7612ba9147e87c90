// cv::ORB wrapped as a FeatureExtractor; see include/orbis/features/opencv_orb_extractor.hpp.
#include "orbis/features/opencv_orb_extractor.hpp"

#include <algorithm>

namespace orbis {

OpenCvOrbExtractor::OpenCvOrbExtractor(const OrbParams& params)
    : PyramidExtractorBase(params),
      orb_(cv::ORB::create(params.features, params.scaleFactor, params.levels, 31, 0, 2,
                           cv::ORB::HARRIS_SCORE, 31, params.iniThFast)) {}

void OpenCvOrbExtractor::extract(const cv::Mat& image, std::vector<Keypoint>& keypoints,
                                 std::vector<OrbDescriptor>& descriptors) {
  const cv::Mat& gray = detail::asGray8u(image, gray_, "OpenCvOrbExtractor input");
  keypoints.clear();
  descriptors.clear();
  if (gray.empty()) return;
  orb_->detectAndCompute(gray, cv::noArray(), cvKeypoints_, cvDescriptors_);
  pyramid_.build(gray, scales_);
  // OpenCV returns keypoints grouped by level already in most versions; make it a guarantee.
  std::vector<std::size_t> order(cvKeypoints_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [this](std::size_t a, std::size_t b) {
    return cvKeypoints_[a].octave < cvKeypoints_[b].octave;
  });
  keypoints.reserve(order.size());
  descriptors.reserve(order.size());
  for (std::size_t i : order) {
    keypoints.push_back(fromCvKeyPoint(cvKeypoints_[i]));
    descriptors.push_back(OrbDescriptor::fromBytes(cvDescriptors_.ptr<std::uint8_t>(static_cast<int>(i))));
  }
}

}  // namespace orbis
