// orbis/features/extractor.hpp — the FeatureExtractor concept every keypoint extractor meets.
//
// Contract: extract(gray, keypoints, descriptors) replaces both outputs with one keypoint and
// one OrbDescriptor per feature (same index), keypoints in level-0 pixels with their octave.
// The input is an 8-bit gray image (CV_8UC1; a 3-channel image is converted, anything else
// throws orbis::Error). After extract(), pyramid() holds that image's scale pyramid (level l
// matching scaleLevels().scale[l]) until the next call: stereo matching correlates patches on
// it. levels()/scaleFactors()/levelSigma2() describe the pyramid and never change.
#pragma once

#include <concepts>
#include <span>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/image_pyramid.hpp"
#include "orbis/features/keypoint.hpp"
#include "orbis/features/orb_params.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

template <class E>
concept FeatureExtractor = requires(E& e, const E& ce, const cv::Mat& image,
                                    std::vector<Keypoint>& keypoints,
                                    std::vector<OrbDescriptor>& descriptors) {
  e.extract(image, keypoints, descriptors);
  { ce.levels() } -> std::convertible_to<int>;
  { ce.scaleFactors() } -> std::convertible_to<std::span<const float>>;
  { ce.levelSigma2() } -> std::convertible_to<std::span<const float>>;
  { ce.scaleLevels() } -> std::convertible_to<const ScaleLevels&>;
  { ce.pyramid() } -> std::convertible_to<std::span<const cv::Mat>>;
};

// The pyramid description and accessors both ORB extractors share.
class PyramidExtractorBase {
 public:
  // Keeps the parameters and the pyramid's scales.
  explicit PyramidExtractorBase(const OrbParams& params)
      : params_(params), scales_(params.levels, params.scaleFactor) {}
  // @{
  // The pyramid's levels, per-level scale factors and σ², the scales, the last image's pyramid and
  // the parameters.
  int levels() const { return scales_.levels(); }
  std::span<const float> scaleFactors() const { return scales_.scale; }
  std::span<const float> levelSigma2() const { return scales_.sigma2; }
  const ScaleLevels& scaleLevels() const { return scales_; }
  std::span<const cv::Mat> pyramid() const { return pyramid_.images(); }
  const OrbParams& params() const { return params_; }
  // @}

 protected:
  // @{
  // The parameters, scales and pyramid the derived extractor fills.
  OrbParams params_;
  ScaleLevels scales_;
  ImagePyramid pyramid_;
  // @}
};

namespace detail {
// Returns `image` if it is 8-bit grey, BGR or BGRA; throws an Error naming `who` otherwise.
inline const cv::Mat& checkGrayOrColour8u(const cv::Mat& image, const char* who) {
  if (image.type() == CV_8UC1 || image.type() == CV_8UC3 || image.type() == CV_8UC4) return image;
  throw Error(who, "", "expected an 8-bit gray or BGR image, got OpenCV type " + std::to_string(image.type()));
}
// Returns `image` if it is already CV_8UC1, else converts a BGR/BGRA image into `scratch`.
inline const cv::Mat& asGray8u(const cv::Mat& image, cv::Mat& scratch, const char* who) {
  if (checkGrayOrColour8u(image, who).type() == CV_8UC1) return image;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image, scratch, cv::COLOR_BGR2GRAY);
    return scratch;
  }
  cv::cvtColor(image, scratch, cv::COLOR_BGRA2GRAY);
  return scratch;
}
}  // namespace detail

}  // namespace orbis
