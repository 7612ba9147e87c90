// Searches on two views of a textured plane with known camera motion: every keypoint of view 1
// has a known 3-D point and a known position in view 2 (the plane-induced homography), so
// each search is checked for finding right matches and for rejecting wrong ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include <Eigen/Geometry>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "features/feature_test_util.hpp"
#include "orbis/features/matcher.hpp"
#include "orbis/features/orb_extractor.hpp"

namespace orbis {
namespace {

constexpr double kPlaneDepth = 3.0;  // plane z = 3 m in camera 1

struct PlaneViews {
  PinholeCamera<double> camera{500.0, 500.0, 320.0, 240.0, 640, 480};
  Eigen::Matrix3d R21;
  Eigen::Vector3d t21;
  Eigen::Matrix3d H21;  // pixel of view 1 -> pixel of view 2
  FrameFeatures f1, f2;

  Eigen::Vector3d pointOf(const Keypoint& k) const {  // on the plane, camera-1 frame
    return camera.unproject(Eigen::Vector2d(k.u, k.v), kPlaneDepth);
  }
  Eigen::Vector2d inView2(const Keypoint& k) const { return camera.project(R21 * pointOf(k) + t21); }
  bool correct(int i1, int i2, double tolerance) const {
    const Eigen::Vector2d p = inView2(f1.keypointsUn[static_cast<std::size_t>(i1)]);
    const Keypoint& k2 = f2.keypointsUn[static_cast<std::size_t>(i2)];
    return (p - Eigen::Vector2d(k2.u, k2.v)).norm() < tolerance;
  }
};

PlaneViews planeViews(double yawDeg, const Eigen::Vector3d& t21, std::uint64_t seed) {
  PlaneViews s;
  s.R21 = Eigen::AngleAxisd(yawDeg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.t21 = t21;
  const Eigen::Matrix3d K = s.camera.K();
  const Eigen::Vector3d n(0, 0, 1);
  s.H21 = K * (s.R21 + t21 * n.transpose() / kPlaneDepth) * K.inverse();
  const cv::Mat img1 = test::texturedImage(640, 480, seed, 1500);
  cv::Mat H;
  cv::eigen2cv(s.H21, H);
  cv::Mat img2;
  cv::warpPerspective(img1, img2, H, img1.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  OrbExtractor ex;
  s.f1 = extractMonocular(ex, img1, s.camera);
  s.f2 = extractMonocular(ex, img2, s.camera);
  return s;
}

struct Tally {
  int matched = 0, correct = 0;
};

TEST(Matcher, SearchByProjectionFindsTrueAndRejectsForeignDescriptors) {
  const PlaneViews s = planeViews(4.0, {0.08, -0.03, 0.05}, 31);
  std::vector<ProjectionQuery> queries;
  for (const Keypoint& k : s.f1.keypointsUn) {
    const Eigen::Vector2d p = s.inView2(k);
    queries.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), -1.f, k.octave, 1.f, {}});
  }
  for (std::size_t i = 0; i < queries.size(); ++i) queries[i].descriptor = s.f1.descriptors[i];
  std::vector<int> matches;
  const int n = searchByProjection(s.f2, std::span<const ProjectionQuery>(queries), 1.f, matching::kRatioStrict, {}, matches);
  Tally t;
  for (std::size_t q = 0; q < matches.size(); ++q)
    if (matches[q] >= 0) {
      ++t.matched;
      t.correct += s.correct(static_cast<int>(q), matches[q], 2.5 * s.f1.scales.scale[static_cast<std::size_t>(s.f1.keypointsUn[q].octave)]);
    }
  EXPECT_EQ(n, t.matched);
  std::printf("[ matcher  ] by projection: %d of %zu queries matched, %d correct\n", t.matched, queries.size(), t.correct);
  EXPECT_GT(t.matched, static_cast<int>(queries.size()) / 3);
  EXPECT_GE(t.correct, t.matched * 95 / 100);
  // One keypoint per query at most.
  std::vector<int> used;
  for (int m : matches)
    if (m >= 0) used.push_back(m);
  std::sort(used.begin(), used.end());
  EXPECT_EQ(std::adjacent_find(used.begin(), used.end()), used.end());

  // The descriptors of other keypoints (a fixed shuffle) at the same predictions: mostly
  // rejected. Unrelated ORB descriptors are correlated enough that kThHigh (100 of 256 bits)
  // lets some through when a window holds a single candidate, as in ORB-SLAM.
  std::vector<ProjectionQuery> foreign = queries;
  std::mt19937 rng(5);
  std::vector<std::size_t> perm(queries.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  for (std::size_t i = 0; i < foreign.size(); ++i) foreign[i].descriptor = queries[perm[i]].descriptor;
  const int wrong = searchByProjection(s.f2, std::span<const ProjectionQuery>(foreign), 1.f, matching::kRatioStrict, {}, matches);
  std::printf("[ matcher  ] by projection with foreign descriptors: %d of %zu matched\n", wrong, queries.size());
  EXPECT_LT(wrong, t.correct / 2);

  // Keypoints marked as taken are never returned.
  std::vector<std::uint8_t> taken(s.f2.size(), 1);
  EXPECT_EQ(searchByProjection(s.f2, std::span<const ProjectionQuery>(queries), 1.f, 0.75f, taken, matches), 0);
}

// Forward motion towards the plane magnifies it by 3 / 2.4 = 1.25: points reappear one octave
// up. With `forward` only octaves >= the last one are searched, which keeps them; the wrong
// (backward) constraint loses most of them.
TEST(Matcher, FrameToFrameRespectsForwardBackwardOctaves) {
  const PlaneViews s = planeViews(0.0, {0.0, 0.0, -0.6}, 32);
  std::vector<TrackedQuery> queries;
  for (std::size_t i = 0; i < s.f1.size(); ++i) {
    const Keypoint& k = s.f1.keypointsUn[i];
    const Eigen::Vector2d p = s.inView2(k);
    queries.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), -1.f, k.octave, k.angle, s.f1.descriptors[i]});
  }
  std::vector<int> fwd, bwd;
  searchFrameToFrame(s.f2, std::span<const TrackedQuery>(queries), 7.f, true, false, true, {}, fwd);
  searchFrameToFrame(s.f2, std::span<const TrackedQuery>(queries), 7.f, false, true, true, {}, bwd);
  Tally tf, tb;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    if (fwd[q] >= 0) {
      ++tf.matched;
      tf.correct += s.correct(static_cast<int>(q), fwd[q], 3.0 * s.f2.scales.scale[static_cast<std::size_t>(s.f2.keypointsUn[static_cast<std::size_t>(fwd[q])].octave)]);
      EXPECT_GE(s.f2.keypointsUn[static_cast<std::size_t>(fwd[q])].octave, queries[q].lastOctave);
    }
    if (bwd[q] >= 0) {
      ++tb.matched;
      tb.correct += s.correct(static_cast<int>(q), bwd[q], 3.0 * s.f2.scales.scale[static_cast<std::size_t>(s.f2.keypointsUn[static_cast<std::size_t>(bwd[q])].octave)]);
      EXPECT_LE(s.f2.keypointsUn[static_cast<std::size_t>(bwd[q])].octave, queries[q].lastOctave);
    }
  }
  std::printf("[ matcher  ] frame to frame, forward motion: forward constraint %d matched / %d correct, "
              "backward constraint %d / %d\n", tf.matched, tf.correct, tb.matched, tb.correct);
  EXPECT_GT(tf.correct, static_cast<int>(queries.size()) / 4);
  EXPECT_GE(tf.correct, tf.matched * 9 / 10);
  EXPECT_GT(tf.correct, tb.correct);
}

TEST(Matcher, InitializationWindowSearchAndRotationCheck) {
  const PlaneViews s = planeViews(25.0, {0.05, 0.02, 0.0}, 33);  // a 25-degree roll
  std::vector<Eigen::Vector2f> predicted;
  for (const Keypoint& k : s.f1.keypointsUn) predicted.emplace_back(k.u, k.v);  // no prior: own position
  std::vector<int> m12;
  const int n = searchForInitialization(s.f1, s.f2, std::span<const Eigen::Vector2f>(predicted), 100.f,
                                        matching::kRatioLoose, true, m12);
  Tally t;
  for (std::size_t i = 0; i < m12.size(); ++i)
    if (m12[i] >= 0) {
      ++t.matched;
      t.correct += s.correct(static_cast<int>(i), m12[i], 3.0);
      EXPECT_EQ(s.f1.keypointsUn[i].octave, 0);
    }
  std::printf("[ matcher  ] initialisation window: %d matched, %d correct\n", t.matched, t.correct);
  EXPECT_EQ(n, t.matched);
  EXPECT_GT(t.matched, 60);
  EXPECT_GE(t.correct, t.matched * 95 / 100);
}

TEST(Matcher, RotationHistogramRejectsInconsistentRotations) {
  RotationHistogram h;
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.f, 2.f);
  std::uniform_real_distribution<float> any(0.f, 360.f);
  for (int i = 0; i < 200; ++i) h.add(-30.f + noise(rng), i);  // consistent: about 330 degrees
  for (int i = 200; i < 240; ++i) h.add(any(rng), i);         // inconsistent
  std::vector<int> out;
  h.rejected(out);
  const auto consistentRejected = std::count_if(out.begin(), out.end(), [](int i) { return i < 200; });
  const auto inconsistentRejected = std::count_if(out.begin(), out.end(), [](int i) { return i >= 200; });
  EXPECT_LT(consistentRejected, 3);
  EXPECT_GT(inconsistentRejected, 30);
}

TEST(Matcher, EpipolarSearchFollowsTheRightGeometry) {
  const PlaneViews s = planeViews(3.0, {0.25, 0.05, 0.02}, 34);
  const Eigen::Matrix3d K = s.camera.K();
  const Eigen::Vector2d ep = s.camera.project(s.t21);  // camera 1's centre seen from camera 2
  EpipolarSearchOptions options;
  std::vector<std::pair<int, int>> pairs;
  const int n = searchForTriangulation(s.f1, s.f2, fundamentalFromPose(s.R21, s.t21, K, K), ep.cast<float>(),
                                       options, pairs);
  int correct = 0;
  for (const auto& [i1, i2] : pairs) correct += s.correct(i1, i2, 3.0 * s.f2.scales.scale[static_cast<std::size_t>(s.f2.keypointsUn[static_cast<std::size_t>(i2)].octave)]);
  // A wrong relative pose (translation along y instead of x) puts the epipolar lines elsewhere.
  const Eigen::Vector3d wrongT(0.02, 0.25, 0.05);
  std::vector<std::pair<int, int>> wrongPairs;
  searchForTriangulation(s.f1, s.f2, fundamentalFromPose(s.R21, wrongT, K, K), s.camera.project(wrongT).cast<float>(),
                         options, wrongPairs);
  int wrongCorrect = 0;
  for (const auto& [i1, i2] : wrongPairs) wrongCorrect += s.correct(i1, i2, 3.0);
  std::printf("[ matcher  ] epipolar: %d pairs, %d correct; with a wrong pose %d pairs, %d correct\n", n,
              correct, static_cast<int>(wrongPairs.size()), wrongCorrect);
  EXPECT_GT(n, static_cast<int>(s.f1.size()) / 4);
  EXPECT_GE(correct, n * 9 / 10);
  EXPECT_LT(wrongCorrect, correct / 3);
  // Groups restrict candidates: with every keypoint of view 2 in another group, nothing matches.
  std::vector<std::uint32_t> g1(s.f1.size(), 1), g2(s.f2.size(), 2);
  options.group1 = g1;
  options.group2 = g2;
  EXPECT_EQ(searchForTriangulation(s.f1, s.f2, fundamentalFromPose(s.R21, s.t21, K, K), ep.cast<float>(), options, pairs), 0);
}

TEST(Matcher, BruteForceCrossCheckAgreesWithOpenCv) {
  const PlaneViews s = planeViews(10.0, {0.1, 0.0, 0.1}, 35);
  const auto ours = bruteForceMatch(std::span<const OrbDescriptor>(s.f1.descriptors),
                                    std::span<const OrbDescriptor>(s.f2.descriptors), 256, true);
  auto toMat = [](const std::vector<OrbDescriptor>& d) {
    cv::Mat m(static_cast<int>(d.size()), 32, CV_8UC1);
    for (std::size_t i = 0; i < d.size(); ++i) std::memcpy(m.ptr(static_cast<int>(i)), d[i].bytes(), 32);
    return m;
  };
  std::vector<cv::DMatch> theirs;
  cv::BFMatcher(cv::NORM_HAMMING, true).match(toMat(s.f1.descriptors), toMat(s.f2.descriptors), theirs);
  ASSERT_EQ(ours.size(), theirs.size());
  for (std::size_t i = 0; i < ours.size(); ++i) {
    EXPECT_EQ(ours[i].query, theirs[i].queryIdx);
    EXPECT_EQ(ours[i].distance, static_cast<int>(theirs[i].distance));
  }
  int correct = 0, good = 0;
  for (const auto& m : ours)
    if (m.distance <= matching::kThLow) {
      ++good;
      correct += s.correct(m.query, m.train, 3.0 * s.f2.scales.scale[static_cast<std::size_t>(s.f2.keypointsUn[static_cast<std::size_t>(m.train)].octave)]);
    }
  std::printf("[ matcher  ] brute force + cross-check: %zu matches, %d within TH_LOW, %d of those correct\n",
              ours.size(), good, correct);
  EXPECT_GE(correct, good * 9 / 10);
  EXPECT_LT(bruteForceMatch(std::span<const OrbDescriptor>(s.f1.descriptors),
                            std::span<const OrbDescriptor>(s.f2.descriptors), 256, false).size(),
            s.f1.size() + 1);
}

}  // namespace
}  // namespace orbis
