// Frame preprocessing: stereo matching with known disparity, RGB-D virtual right coordinate,
// close/far tagging, the feature grid; plus the share of stereo matches on real pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <opencv2/imgproc.hpp>

#include "features/feature_test_util.hpp"
#include "orbis/camera/euroc_calibration.hpp"
#include "orbis/camera/rectification.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/features/orb_extractor.hpp"
#include "test_data.hpp"

namespace orbis {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// A slanted textured plane seen by a rectified pair: disparity d = a + b uR + c v (affine in
// the right image for a plane), so R(uR, v) = L(uR + d, v) and, at a left keypoint,
// uR = (uL - a - c v) / (1 + b). Both views are rendered alike, as a camera would: sampled at
// twice the resolution, area-averaged down, then a mild optical blur.
struct SlantedPlanePair {
  cv::Mat left, right;
  double a, b, c;
  double trueDisparity(double uL, double v) const { return uL - (uL - a - c * v) / (1 + b); }
};

SlantedPlanePair slantedPlane(double a, double b, double c, std::uint64_t seed) {
  constexpr int kSuper = 2, kW = 640, kH = 480;
  const cv::Mat fine = test::texturedImage(kW * kSuper, kH * kSuper, seed, 1200 * kSuper * kSuper);
  cv::Mat mapX(kH * kSuper, kW * kSuper, CV_32FC1), mapY(kH * kSuper, kW * kSuper, CV_32FC1);
  for (int y = 0; y < kH * kSuper; ++y)
    for (int x = 0; x < kW * kSuper; ++x) {
      // Fine pixel centre -> image coordinates -> shifted by the disparity -> fine pixel.
      const double xr = (x + 0.5) / kSuper - 0.5, yr = (y + 0.5) / kSuper - 0.5;
      mapX.at<float>(y, x) = static_cast<float>((xr + a + b * xr + c * yr + 0.5) * kSuper - 0.5);
      mapY.at<float>(y, x) = static_cast<float>(y);
    }
  cv::Mat fineRight;
  cv::remap(fine, fineRight, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  SlantedPlanePair s{{}, {}, a, b, c};
  cv::resize(fine, s.left, cv::Size(kW, kH), 0, 0, cv::INTER_AREA);
  cv::resize(fineRight, s.right, cv::Size(kW, kH), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(s.left, s.left, cv::Size(0, 0), 0.8);
  cv::GaussianBlur(s.right, s.right, cv::Size(0, 0), 0.8);
  return s;
}

RectifiedStereoCamera<double> syntheticRig() {
  PinholeCamera<double> pin{400.0, 400.0, 320.0, 240.0, 640, 480};
  return {pin, 0.1};  // bf = 40: disparity 10 px is 4 m, close below 4 m (40 baselines)
}

struct DisparityStats {
  double share = 0, medianError = 0;
  int beyond2px = 0;
};

DisparityStats disparityStats(const FrameFeatures& f, const SlantedPlanePair& pair) {
  std::vector<double> errors;
  DisparityStats s;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f.uRight[i] < 0) {
      EXPECT_LT(f.depth[i], 0.f);
      continue;
    }
    const double disparity = f.keypoints[i].u - f.uRight[i];
    const double e = std::abs(disparity - pair.trueDisparity(f.keypoints[i].u, f.keypoints[i].v));
    errors.push_back(e);
    s.beyond2px += e > 2.0;
    EXPECT_NEAR(f.depth[i], 40.0 / disparity, 1e-3 * f.depth[i]);
  }
  s.share = double(errors.size()) / double(f.size());
  s.medianError = median(errors);
  return s;
}

TEST(StereoMatcher, RecoversKnownDisparityOnSyntheticPlane) {
  const SlantedPlanePair pair = slantedPlane(12.0, 0.012, 0.008, 21);  // 12 .. 23.5 px
  OrbParams wider;
  wider.features = 2000;
  OrbExtractor left, right, rightWider(wider);
  StereoMatcher matcher;
  // ORB-SLAM's setting (same budget both sides) and a right image with twice the budget: the
  // quadtree picks different corners in the two views, more right keypoints find more partners.
  const DisparityStats same = disparityStats(extractStereo(left, right, pair.left, pair.right, syntheticRig(), matcher), pair);
  const DisparityStats twice = disparityStats(extractStereo(left, rightWider, pair.left, pair.right, syntheticRig(), matcher), pair);
  for (const auto& [name, s] : {std::pair{"same budget", same}, std::pair{"right budget x2", twice}})
    std::printf("[ stereo   ] synthetic slanted plane, %s: %.1f%% of left keypoints matched, median "
                "|disparity error| %.3f px, %d beyond 2 px\n", name, 100 * s.share, s.medianError, s.beyond2px);
  EXPECT_GT(same.share, 0.5);
  EXPECT_GT(twice.share, 0.70);
  EXPECT_LT(same.medianError, 0.3);
  EXPECT_LT(twice.medianError, 0.3);
  EXPECT_LT(twice.beyond2px, 10);
}

// The left keypoints split between the caller and the matcher's helper give the serial output,
// bit for bit, call after call (the helper is kept between calls).
TEST(StereoMatcher, TwoThreadsGiveTheSerialBits) {
  for (const std::uint64_t seed : {21u, 22u, 23u}) {
    const SlantedPlanePair pair = slantedPlane(12.0, 0.012, 0.008, seed);
    OrbExtractor left, right;
    std::vector<Keypoint> kl, kr;
    std::vector<OrbDescriptor> dl, dr;
    left.extract(pair.left, kl, dl);
    right.extract(pair.right, kr, dr);
    ASSERT_GE(kl.size(), StereoMatcher::kMinKeypointsForTwoThreads);
    const StereoView l{kl, dl, left.pyramid()}, r{kr, dr, right.pyramid()};
    StereoMatcher serial, parallel;
    parallel.setParallel(true);
    std::vector<float> uSerial, dSerial, uParallel, dParallel;
    serial.match(l, r, left.scaleLevels(), 40.f, 0.1f, uSerial, dSerial);
    parallel.match(l, r, left.scaleLevels(), 40.f, 0.1f, uParallel, dParallel);
    EXPECT_GT(std::count_if(uSerial.begin(), uSerial.end(), [](float u) { return u >= 0; }), static_cast<long>(kl.size()) / 3);
    EXPECT_TRUE(uSerial == uParallel) << "seed " << seed;
    EXPECT_TRUE(dSerial == dParallel) << "seed " << seed;
  }
}

TEST(StereoMatcher, RejectsDisparitiesBeyondTheRange) {
  // Every point has disparity 30 px; with minDepth such that bf/minDepth = 20 px nothing may
  // match, with a generous range almost everything must.
  const SlantedPlanePair pair = slantedPlane(30.0, 0.0, 0.0, 5);
  OrbExtractor left, right;
  std::vector<Keypoint> kl, kr;
  std::vector<OrbDescriptor> dl, dr;
  left.extract(pair.left, kl, dl);
  right.extract(pair.right, kr, dr);
  StereoMatcher matcher;
  std::vector<float> uR, depth;
  const StereoView l{kl, dl, left.pyramid()}, r{kr, dr, right.pyramid()};
  matcher.match(l, r, left.scaleLevels(), 40.f, 2.f, uR, depth);  // max disparity 20
  // Only chance look-alikes can match when the true partner is out of range.
  EXPECT_LT(std::count_if(uR.begin(), uR.end(), [](float u) { return u >= 0; }), static_cast<long>(kl.size()) / 100);
  matcher.match(l, r, left.scaleLevels(), 40.f, 0.1f, uR, depth);  // max disparity 400
  const auto matched = std::count_if(uR.begin(), uR.end(), [](float u) { return u >= 0; });
  EXPECT_GT(matched, static_cast<long>(kl.size()) * 4 / 10);
}

TEST(FrameFeatures, CloseAndFarFollowTheDepthThreshold) {
  const SlantedPlanePair pair = slantedPlane(12.0, 0.012, 0.008, 21);  // depths 1.7 .. 3.3 m
  OrbExtractor left, right;
  StereoMatcher matcher;
  RectifiedStereoCamera<double> rig = syntheticRig();
  rig.closeDepth = 2.5;
  const FrameFeatures f = extractStereo(left, right, pair.left, pair.right, rig, matcher);
  int close = 0, far = 0, mono = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    switch (f.kind(i)) {
      case KeypointKind::Close: ++close; EXPECT_LT(f.depth[i], 2.5f); break;
      case KeypointKind::Far: ++far; EXPECT_GE(f.depth[i], 2.5f); break;
      case KeypointKind::Monocular: ++mono; EXPECT_LT(f.uRight[i], 0.f); break;
    }
  }
  EXPECT_GT(close, 50);
  EXPECT_GT(far, 50);
  EXPECT_EQ(static_cast<std::size_t>(close + far), f.stereoCount());
}

TEST(FrameFeatures, RgbdVirtualRightCoordinateAndInvalidDepth) {
  const cv::Mat img = test::texturedImage(640, 480, 8);
  // Depth 1 + x/640 metres, raw 16-bit at factor 5000; a hole (0) on the left quarter.
  cv::Mat raw(480, 640, CV_16UC1);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x)
      raw.at<std::uint16_t>(y, x) = x < 160 ? 0 : static_cast<std::uint16_t>(5000.0 * (1.0 + x / 640.0));
  const RgbdCamera<double> cam({535.4, 539.2, 320.1, 247.6, 640, 480}, 40.0 / 535.4, 5000.0);
  OrbExtractor ex;
  const FrameFeatures f = extractRgbd(ex, img, raw, cam);
  int withDepth = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& k = f.keypoints[i];
    const int u = static_cast<int>(std::lround(k.u));
    if (u < 160) {
      EXPECT_EQ(f.kind(i), KeypointKind::Monocular) << "hole at u=" << k.u;
      continue;
    }
    ++withDepth;
    const double d = raw.at<std::uint16_t>(static_cast<int>(std::lround(k.v)), u) / 5000.0;
    EXPECT_NEAR(f.depth[i], d, 1e-6);
    EXPECT_NEAR(f.uRight[i], f.keypointsUn[i].u - 40.0 / d, 1e-3);
    EXPECT_EQ(f.kind(i), KeypointKind::Close);  // 1..2 m, close below 40 x 0.0747 m
  }
  EXPECT_GT(withDepth, 500);

  // The same through a float depth image in metres-times-factor, with NaN where unknown.
  cv::Mat asFloat;
  raw.convertTo(asFloat, CV_32FC1);
  asFloat.colRange(0, 160).setTo(std::numeric_limits<float>::quiet_NaN());
  const FrameFeatures g = extractRgbd(ex, img, asFloat, cam);
  ASSERT_EQ(g.size(), f.size());
  for (std::size_t i = 0; i < g.size(); ++i) EXPECT_EQ(g.depth[i], f.depth[i]);

  cv::Mat wrongType(480, 640, CV_8UC1, cv::Scalar(1));
  EXPECT_THROW(extractRgbd(ex, img, wrongType, cam), Error);
}

TEST(FeatureGrid, AreaQueriesEqualBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> ux(-5.f, 645.f), uy(-5.f, 485.f);
  std::uniform_int_distribution<int> level(0, 7);
  std::vector<Keypoint> kps(3000);
  for (auto& k : kps) k = {ux(rng), uy(rng), 0.f, 1.f, level(rng)};
  FeatureGrid grid;
  grid.build(kps, 0.f, 640.f, 0.f, 480.f);
  std::vector<int> got;
  for (int q = 0; q < 300; ++q) {
    const float u = ux(rng), v = uy(rng), r = 2.f + static_cast<float>(q % 60);
    const int minL = q % 3 == 0 ? -1 : level(rng), maxL = q % 4 == 0 ? -1 : std::max(minL, level(rng));
    grid.featuresInArea(u, v, r, minL, maxL, got);
    std::vector<int> want;
    for (std::size_t i = 0; i < kps.size(); ++i) {
      const auto& k = kps[i];
      if (!grid.inBounds(k.u, k.v)) continue;
      if (minL >= 0 && k.octave < minL) continue;
      if (maxL >= 0 && k.octave > maxL) continue;
      if (std::abs(k.u - u) < r && std::abs(k.v - v) < r) want.push_back(static_cast<int>(i));
    }
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, want) << "query " << q;
  }
}

// Real rectified pairs: the share of left keypoints with a stereo match, printed.
struct RealPairStats {
  double share = 0, medianDepth = 0;
};

template <class LoadPair>
RealPairStats matchRealPairs(std::size_t pairs, int budget, const RectifiedStereoCamera<double>& camera,
                             LoadPair loadPair) {
  OrbParams p;
  p.features = budget;
  OrbExtractor left(p), right(p);
  StereoMatcher matcher;
  std::size_t matched = 0, total = 0;
  std::vector<double> depths;
  for (std::size_t i = 0; i < pairs; ++i) {
    const auto [l, r] = loadPair(i);
    const FrameFeatures f = extractStereo(left, right, l, r, camera, matcher);
    matched += f.stereoCount();
    total += f.size();
    for (float d : f.depth)
      if (d > 0) depths.push_back(d);
  }
  return {double(matched) / double(total), median(depths)};
}

TEST(StereoMatcher, ShareMatchedOnRectifiedEuroc) {
  ORBIS_REQUIRE_DATASET(euroc, "euroc_V1_01_easy_95");
  const auto rect = rectifyStereo(readEurocCalibration(euroc / "mav0/cam0/sensor.yaml"),
                                  readEurocCalibration(euroc / "mav0/cam1/sensor.yaml"));
  const auto lefts = test::sortedPngs(euroc / "mav0/cam0/data", 5);
  const auto rights = test::sortedPngs(euroc / "mav0/cam1/data", 5);
  const RealPairStats s = matchRealPairs(lefts.size(), 1200, rect.camera, [&](std::size_t i) {
    const auto pair = rect.rectify(test::readGray(lefts[i]), test::readGray(rights[i]));
    return std::pair{pair.left, pair.right};
  });
  std::printf("[ stereo   ] EuRoC V1_01 rectified, 5 pairs: %.1f%% of left keypoints matched, "
              "median depth %.2f m\n", 100 * s.share, s.medianDepth);
  EXPECT_GT(s.share, 0.3);
  EXPECT_GT(s.medianDepth, 1.0);  // a room a few metres across
  EXPECT_LT(s.medianDepth, 8.0);
}

TEST(StereoMatcher, ShareMatchedOnKitti) {
  ORBIS_REQUIRE_DATASET(kitti, "kitti_06_first51");
  const PinholeCamera<double> pin{707.0912, 707.0912, 601.8873, 183.1104, 1226, 370};
  const RectifiedStereoCamera<double> cam(pin, 379.8145 / 707.0912);
  const auto lefts = test::sortedPngs(kitti / "sequences/06/image_0", 3);
  const auto rights = test::sortedPngs(kitti / "sequences/06/image_1", 3);
  const RealPairStats s = matchRealPairs(lefts.size(), 2000, cam, [&](std::size_t i) {
    return std::pair{test::readGray(lefts[i]), test::readGray(rights[i])};
  });
  std::printf("[ stereo   ] KITTI 06, 3 pairs: %.1f%% of left keypoints matched, median depth %.1f m\n",
              100 * s.share, s.medianDepth);
  EXPECT_GT(s.share, 0.3);
  EXPECT_GT(s.medianDepth, 5.0);  // a road scene
}

TEST(FrameFeatures, RgbdShareWithDepthOnTum) {
  ORBIS_REQUIRE_DATASET(tum, "tum_fr3_teddy_200");
  const cv::Mat img = test::readGray(test::sortedPngs(tum / "rgb", 1).at(0));
  const cv::Mat depth = cv::imread((test::sortedPngs(tum / "depth", 1).at(0)).string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16UC1);
  const RgbdCamera<double> cam({535.4, 539.2, 320.1, 247.6, 640, 480}, 40.0 / 535.4, 5000.0);
  OrbExtractor ex;
  const FrameFeatures f = extractRgbd(ex, img, depth, cam);
  const double share = double(f.stereoCount()) / double(f.size());
  std::printf("[ rgbd     ] TUM teddy frame 0: %.1f%% of keypoints have depth\n", 100 * share);
  EXPECT_GT(share, 0.5);
}

}  // namespace
}  // namespace orbis
