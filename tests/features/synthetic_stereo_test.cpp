// Stereo keypoints on the project's synthetic stereo sequence (orbis/synth): rendered pairs
// with exact metric depth, so every stereo match has a known true disparity bf / Z.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "orbis/features/frame_features.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/sensor/sensor.hpp"
#include "orbis/synth/sequence.hpp"

namespace orbis {
namespace {

struct SyntheticStereoStats {
  double share = 0, medianError = 0;
  double meanSignedError = 0;  // disparity - bf/Z over the matches within 1 px of the truth
  std::size_t keypoints = 0, matched = 0;
};

SyntheticStereoStats runSynthetic(int rightFeaturesFactor) {
  synth::SynthOptions options;
  options.frames = 60;
  synth::SyntheticSequence sequence(options);
  const PinholeCamera<double> pinhole = sequence.camera();
  const RectifiedStereoCamera<double> camera(pinhole, options.baseline);
  OrbParams orb;
  orb.rightFeaturesFactor = rightFeaturesFactor;
  Stereo::FeatureBuilder builder(camera, orb);  // the pipeline's stereo front end
  std::vector<double> errors;
  double signedSum = 0;
  std::size_t signedCount = 0;
  SyntheticStereoStats s;
  for (int i : {0, 20, 40}) {
    const synth::SynthFrame frame = sequence.render(i, true, true);
    const FrameFeatures f = builder.build({0.0, frame.left, frame.right});
    s.keypoints += f.size();
    for (std::size_t k = 0; k < f.size(); ++k) {
      if (f.uRight[k] < 0) continue;
      ++s.matched;
      const float z = frame.depth.at<float>(static_cast<int>(std::lround(f.keypoints[k].v)),
                                            static_cast<int>(std::lround(f.keypoints[k].u)));
      if (!(z > 0)) continue;
      const double error = (f.keypoints[k].u - f.uRight[k]) - camera.bf() / z;
      errors.push_back(std::abs(error));
      if (std::abs(error) < 1.0) {  // beyond a pixel: a wrong partner or a depth edge, not bias
        signedSum += error;
        ++signedCount;
      }
    }
  }
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
  s.medianError = errors.empty() ? 1e9 : errors[errors.size() / 2];
  s.share = double(s.matched) / double(s.keypoints);
  s.meanSignedError = signedCount ? signedSum / double(signedCount) : 1e9;
  return s;
}

TEST(StereoMatcher, SyntheticSequenceDisparityAndShare) {
  const SyntheticStereoStats same = runSynthetic(1);
  const SyntheticStereoStats wider = runSynthetic(3);
  for (const auto& [name, s] : {std::pair{"same budget", same}, std::pair{"right budget x3", wider}})
    std::printf("[ stereo   ] synth room, 3 frames, %s: %zu of %zu left keypoints matched (%.1f%%), "
                "median |disparity - bf/Z| %.3f px, mean disparity - bf/Z %+.4f px\n", name, s.matched, s.keypoints,
                100 * s.share, s.medianError, s.meanSignedError);
  // Zero-mean patches (0.097 px measured; each patch minus its centre pixel, as ORB-SLAM2: 0.29).
  EXPECT_LT(same.medianError, 0.15);
  EXPECT_LT(wider.medianError, 0.15);
  // No systematic disparity error (measured +0.002 / +0.003 px): a bias of b px scales every
  // depth by 1 - b/d, and with it the trajectory (issue 18: KITTI's scale error, 0.2 %, would
  // need -0.08 px at the typical close disparity of 40 px).
  EXPECT_LT(std::abs(same.meanSignedError), 0.02);
  EXPECT_LT(std::abs(wider.meanSignedError), 0.02);
  // With ORB-SLAM's equal budgets about 55% match: the quadtree keeps different corners in the
  // two views, and 924 of the 3012 left keypoints have no right keypoint within 1.5 px x scale
  // of their true partner (38 more fall outside the right view), so no matcher could pass ~69%.
  // Three times the budget on the right (ORBextractor.rightFeaturesFactor: 3) leaves 349
  // without one and matches over 70%. Why the default stays at 1: Stereo in sensor/sensor.hpp.
  EXPECT_GT(same.share, 0.5);
  EXPECT_GT(wider.share, 0.7);
  EXPECT_GT(wider.share, same.share);
}

}  // namespace
}  // namespace orbis
