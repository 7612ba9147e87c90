// The synthetic frames as the tracker will see them: the project's ORB extractor fills every
// pyramid level, and ORB matches between consecutive frames agree with the ground-truth poses
// and depth (the images, the poses and the depth maps tell one consistent story).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "orbis/features/descriptor.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "orbis/synth/sequence.hpp"

namespace orbis::synth {
namespace {

TEST(SynthFeatures, OrbExtractorFillsEveryLevelsBudget) {
  SynthOptions o;  // VGA, 300 frames, as `orbis synth` writes them
  SyntheticSequence seq(o);
  OrbExtractor extractor;
  std::vector<Keypoint> keypoints;
  std::vector<OrbDescriptor> descriptors;
  for (int i : {0, 100, 200}) {
    extractor.extract(seq.render(i, false, false).left, keypoints, descriptors);
    std::vector<int> perLevel(static_cast<std::size_t>(extractor.levels()), 0);
    for (const Keypoint& k : keypoints) ++perLevel[static_cast<std::size_t>(k.octave)];
    for (int l = 0; l < extractor.levels(); ++l)
      EXPECT_GE(perLevel[static_cast<std::size_t>(l)], 0.95 * extractor.featuresPerLevel()[static_cast<std::size_t>(l)])
          << "frame " << i << " level " << l;
  }
}

TEST(SynthFeatures, OrbMatchesBetweenFramesAgreeWithGroundTruth) {
  SynthOptions o;
  o.noiseSigma = 2.0;
  SyntheticSequence seq(o);
  const PinholeCamera<double> cam = seq.camera();
  OrbExtractor extractor;
  for (int i : {0, 150}) {
    const SynthFrame a = seq.render(i, false, true);
    const SynthFrame b = seq.render(i + 1, false, false);
    std::vector<Keypoint> ka, kb;
    std::vector<OrbDescriptor> da, db;
    extractor.extract(a.left, ka, da);
    extractor.extract(b.left, kb, db);
    const SE3d aToB = b.pose.inverse() * a.pose;
    std::vector<double> errors;
    for (std::size_t p = 0; p < ka.size(); ++p) {
      // Best and second-best match by brute force; keep distinctive ones on the same level.
      int best = 256, second = 256;
      std::size_t bestIndex = 0;
      for (std::size_t q = 0; q < kb.size(); ++q) {
        const int d = hammingDistance(da[p], db[q]);
        if (d < best) {
          second = best;
          best = d;
          bestIndex = q;
        } else if (d < second) {
          second = d;
        }
      }
      if (best > 50 || best > 0.7 * second) continue;
      const float z = a.depth.at<float>(static_cast<int>(std::lround(ka[p].v)), static_cast<int>(std::lround(ka[p].u)));
      const Eigen::Vector3d pb = aToB * cam.unproject(Eigen::Vector2d(ka[p].u, ka[p].v), z);
      const Eigen::Vector2d predicted = cam.project(pb);
      const double scale = std::pow(1.2, kb[bestIndex].octave);  // keypoint precision falls with the level
      errors.push_back((predicted - Eigen::Vector2d(kb[bestIndex].u, kb[bestIndex].v)).norm() / scale);
    }
    ASSERT_GT(errors.size(), 300u) << "frame " << i;
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2];
    const auto within = std::count_if(errors.begin(), errors.end(), [](double e) { return e < 3.0; });
    std::printf("frames %d-%d: %zu ORB matches, median reprojection error %.2f px (level-scaled), %.1f%% within 3 px\n",
                i, i + 1, errors.size(), median, 100.0 * within / errors.size());
    EXPECT_LT(median, 1.0) << "frame " << i;
    EXPECT_GT(within, 0.95 * errors.size()) << "frame " << i;
  }
}

}  // namespace
}  // namespace orbis::synth
