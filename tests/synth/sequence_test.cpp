// Synthetic sequences: determinism, the closed loop, options (noise, blur, black frames), and
// the two properties SLAM needs from the images: corners at every pyramid level, and stereo
// pairs whose block-matched disparity agrees with the ground-truth depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/synth/sequence.hpp"
#include "orbis/util/error.hpp"

namespace orbis::synth {
namespace {

SynthOptions smallOptions() {
  SynthOptions o;
  o.frames = 40;
  o.width = 320;
  o.height = 240;
  o.fx = 250.0;
  return o;
}

double rotationAngle(const SE3d& a, const SE3d& b) { return (a.inverse() * b).so3().log().norm(); }

TEST(SynthSequence, SameSeedGivesIdenticalFramesInAnyOrder) {
  SynthOptions o = smallOptions();
  o.noiseSigma = 3.0;
  o.blurSubframes = 3;
  SyntheticSequence a(o), b(o);
  const SynthFrame fa = a.render(7, true, true);
  b.render(2, true, false);  // a different history must not matter
  const SynthFrame fb = b.render(7, true, true);
  EXPECT_EQ(cv::norm(fa.left, fb.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.right, fb.right, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.depth, fb.depth, cv::NORM_INF), 0.0);

  o.seed = 2;
  SyntheticSequence c(o);
  const SynthFrame fc = c.render(7, false, false);
  EXPECT_GT(cv::norm(fa.left, fc.left, cv::NORM_L1) / fa.left.total(), 10.0) << "another seed, another scene";
}

TEST(SynthSequence, TrajectoryIsASmoothClosedLoop) {
  SynthOptions o = smallOptions();
  o.frames = 300;
  const SyntheticSequence seq(o);
  double maxStep = 0.0, minStep = 1e9, maxTurn = 0.0, stepSum = 0.0;
  for (int i = 0; i + 1 < o.frames; ++i) {
    const double step = (seq.pose(i + 1).translation() - seq.pose(i).translation()).norm();
    maxStep = std::max(maxStep, step);
    minStep = std::min(minStep, step);
    maxTurn = std::max(maxTurn, rotationAngle(seq.pose(i), seq.pose(i + 1)));
    stepSum += step;
  }
  EXPECT_GT(minStep, 0.01) << "the camera keeps moving";
  EXPECT_LT(maxStep, 0.06);
  EXPECT_LT(maxTurn, 3.0 * M_PI / 180.0);
  EXPECT_GT(stepSum, 8.0) << "one loop of the default ellipse is about 11 m";
  // The last frame is one ordinary step before the first: the loop closes.
  const SE3d last = seq.pose(o.frames - 1), first = seq.pose(0);
  EXPECT_LT((last.translation() - first.translation()).norm(), maxStep * 1.001);
  EXPECT_LT(rotationAngle(last, first), maxTurn * 1.001);
  EXPECT_GT((seq.pose(o.frames / 2).translation() - first.translation()).norm(), 2.5) << "it goes somewhere";
  const SE3d again = loopPose(o.path, 1.0);
  EXPECT_LT((again.translation() - first.translation()).norm(), 1e-12);
  EXPECT_LT(rotationAngle(again, first), 1e-9);
  // Timestamps: fps apart, strictly increasing.
  EXPECT_NEAR(seq.timestamp(30) - seq.timestamp(0), 1.0, 1e-9);
}

TEST(SynthSequence, FastFindsCornersAtEveryPyramidLevel) {
  SynthOptions o;  // VGA, as the sequences are written
  o.frames = 8;
  SyntheticSequence seq(o);
  const auto fast = cv::FastFeatureDetector::create(20);
  for (int i : {0, 3, 6}) {
    const cv::Mat image = seq.render(i, false, false).left;
    cv::Mat level = image;
    for (int l = 0; l < 8; ++l) {
      std::vector<cv::KeyPoint> corners;
      fast->detect(level, corners);
      // ORB-SLAM2 asks ~1000 features of 8 levels; a level needs far more candidates than its share.
      EXPECT_GT(corners.size(), 300u) << "frame " << i << " level " << l << " (" << level.cols << "x" << level.rows << ")";
      cv::Mat next;
      cv::resize(level, next, cv::Size(), 1.0 / 1.2, 1.0 / 1.2, cv::INTER_LINEAR);
      level = next;
    }
  }
}

TEST(SynthSequence, BlockMatchedDisparityAgreesWithDepth) {
  SynthOptions o = smallOptions();
  o.baseline = 0.2;
  SyntheticSequence seq(o);
  const double bf = o.fx * o.baseline;
  std::vector<double> errors;
  for (int i : {0, 13, 27}) {
    const SynthFrame f = seq.render(i, true, true);
    cv::Mat left, right;
    f.left.convertTo(left, CV_32F);
    f.right.convertTo(right, CV_32F);
    const int r = 4;
    for (int y = 20; y < o.height - 20; y += 7)
      for (int x = 40; x < o.width - 20; x += 7) {
        // Smooth depth around the pixel: no silhouette inside the block.
        const cv::Mat patchDepth = f.depth(cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1));
        double dmin, dmax;
        cv::minMaxLoc(patchDepth, &dmin, &dmax);
        if (dmax - dmin > 0.05 * dmin) continue;
        const cv::Mat patch = left(cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1));
        cv::Scalar mean, stddev;
        cv::meanStdDev(patch, mean, stddev);
        if (stddev[0] < 15.0) continue;  // too flat to match
        const double expected = bf / f.depth.at<float>(y, x);
        // SSD over integer disparities 0 .. 30, then a parabola through the best three.
        std::vector<double> cost;
        for (int d = 0; d <= 30 && x - d - r >= 0; ++d)
          cost.push_back(cv::norm(patch, right(cv::Rect(x - d - r, y - r, 2 * r + 1, 2 * r + 1)), cv::NORM_L2SQR));
        const auto best = std::min_element(cost.begin(), cost.end()) - cost.begin();
        if (best == 0 || best + 1 >= static_cast<long>(cost.size())) continue;
        const double c0 = cost[best - 1], c1 = cost[best], c2 = cost[best + 1];
        const double measured = best + 0.5 * (c0 - c2) / (c0 - 2.0 * c1 + c2);
        errors.push_back(std::abs(measured - expected));
      }
  }
  ASSERT_GT(errors.size(), 300u);
  std::sort(errors.begin(), errors.end());
  std::printf("block-matched disparity vs bf/Z over %zu pixels: median %.3f px, 90%% %.3f px\n", errors.size(),
              errors[errors.size() / 2], errors[errors.size() * 9 / 10]);
  EXPECT_LT(errors[errors.size() / 2], 0.15) << "median disparity error (px)";
  EXPECT_LT(errors[errors.size() * 9 / 10], 0.5) << "90th percentile disparity error (px)";
}

TEST(SynthSequence, NoiseHasTheRequestedSigma) {
  SynthOptions clean = smallOptions();
  SynthOptions noisy = clean;
  noisy.noiseSigma = 4.0;
  const SynthFrame a = SyntheticSequence(clean).render(5, false, false);
  const SynthFrame b = SyntheticSequence(noisy).render(5, false, false);
  cv::Mat diff;
  cv::subtract(b.left, a.left, diff, cv::noArray(), CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(diff, mean, stddev);
  EXPECT_NEAR(stddev[0], 4.0, 0.15);  // rounding adds ~1/12 of a grey level's variance
  EXPECT_NEAR(mean[0], 0.0, 0.1);
}

TEST(SynthSequence, DepthNoiseIsOnTheInverseAndLeavesImagesAlone) {
  SynthOptions clean = smallOptions();
  SynthOptions noisy = clean;
  noisy.depthNoise = 0.01;  // 1/m
  const SynthFrame a = SyntheticSequence(clean).render(5, false, true);
  const SynthFrame b = SyntheticSequence(noisy).render(5, false, true);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int y = 0; y < a.depth.rows; ++y)
    for (int x = 0; x < a.depth.cols; ++x) {
      const float da = a.depth.at<float>(y, x), db = b.depth.at<float>(y, x);
      if (da <= 0.f || db <= 0.f) continue;
      const double e = 1.0 / db - 1.0 / da;
      sum += e;
      sum2 += e * e;
      ++n;
    }
  ASSERT_GT(n, 1000);
  const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
  std::printf("[synth] depth noise: inverse-depth error mean %.2e, sigma %.5f 1/m over %d pixels\n", mean, sigma, n);
  EXPECT_NEAR(sigma, 0.01, 0.0005);
  EXPECT_NEAR(mean, 0.0, 0.0005);
  EXPECT_EQ(cv::norm(b.depth, SyntheticSequence(noisy).render(5, false, true).depth, cv::NORM_INF), 0.0);  // same seed, same noise
}

TEST(SynthSequence, MotionBlurSmoothsAlongTheMotion) {
  SynthOptions sharp = smallOptions();
  sharp.frames = 300;  // the default pace: about 4 cm and 1.2 degrees per frame
  SynthOptions blurred = sharp;
  blurred.blurSubframes = 5;
  blurred.shutter = 1.0;
  const auto gradientEnergy = [](const cv::Mat& image) {
    cv::Mat gx;
    cv::Sobel(image, gx, CV_32F, 1, 0);
    return cv::norm(gx, cv::NORM_L2SQR) / static_cast<double>(image.total());
  };
  const SynthFrame a = SyntheticSequence(sharp).render(10, false, false);
  const SynthFrame b = SyntheticSequence(blurred).render(10, false, false);
  EXPECT_LT(gradientEnergy(b.left), 0.9 * gradientEnergy(a.left));
  // A blurred frame is still the same view: it correlates strongly with the sharp one.
  cv::Mat fa, fb, result;
  a.left.convertTo(fa, CV_32F);
  b.left.convertTo(fb, CV_32F);
  cv::matchTemplate(fa, fb, result, cv::TM_CCOEFF_NORMED);
  EXPECT_GT(result.at<float>(0, 0), 0.8f);
  // Depth is the frame's instant, unblurred, for odd and even sub-frame counts alike.
  const SynthFrame sharpDepth = SyntheticSequence(sharp).render(10, false, true);
  for (int subframes : {4, 5}) {
    blurred.blurSubframes = subframes;
    const SynthFrame f = SyntheticSequence(blurred).render(10, false, true);
    EXPECT_EQ(cv::norm(f.depth, sharpDepth.depth, cv::NORM_INF), 0.0) << subframes << " sub-frames";
  }
}

TEST(SynthSequence, BlackSegmentIsBlackWithInvalidDepthButKeepsItsPose) {
  SynthOptions o = smallOptions();
  o.blackStart = 10;
  o.blackCount = 5;
  SyntheticSequence seq(o);
  for (int i : {9, 10, 14, 15}) {
    const SynthFrame f = seq.render(i, true, true);
    const bool black = i >= 10 && i < 15;
    EXPECT_EQ(f.black, black) << i;
    EXPECT_EQ(cv::countNonZero(f.left) == 0, black) << i;
    EXPECT_EQ(cv::countNonZero(f.right) == 0, black) << i;
    EXPECT_EQ(cv::countNonZero(f.depth) == 0, black) << i;
    EXPECT_LT((f.pose.translation() - seq.pose(i).translation()).norm(), 1e-15);
  }
}

TEST(SynthSequence, RejectsBadOptionsNamingThem) {
  SynthOptions o = smallOptions();
  o.frames = 0;
  try {
    SyntheticSequence s(o);
    FAIL() << "frames = 0 accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.where(), "key frames");
  }
  o = smallOptions();
  o.baseline = -1.0;
  EXPECT_THROW(SyntheticSequence{o}, Error);
  o = smallOptions();
  o.blackStart = -3;
  o.blackCount = 2;
  EXPECT_THROW(SyntheticSequence{o}, Error);
}

}  // namespace
}  // namespace orbis::synth
