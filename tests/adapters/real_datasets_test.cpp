// Every frame of each real sequence in ../shared/datasets read through the adapters; frame
// counts, stereo/depth completeness and ground-truth coverage printed and checked.
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cstdio>

#include "orbis/adapters/dataset.hpp"
#include "orbis/util/error.hpp"
#include "test_data.hpp"

namespace {

struct ReadSummary {
  std::size_t frames = 0, withRight = 0, withDepth = 0, warnings = 0, groundTruthMatched = 0;
};

// Reads every frame in order and counts what came with it; ground truth matched within 20 ms.
ReadSummary readAll(orbis::DatasetReader& reader, int expectedLeftType) {
  ReadSummary s;
  double previous = -1e300;
  while (auto frame = reader.next()) {
    EXPECT_EQ(frame->index, s.frames);
    EXPECT_GT(frame->timestamp, previous);
    previous = frame->timestamp;
    EXPECT_EQ(frame->left.type(), expectedLeftType) << "frame " << s.frames;
    if (!frame->right.empty()) {
      ++s.withRight;
      EXPECT_EQ(frame->right.size(), frame->left.size());
    }
    if (!frame->depth.empty()) {
      ++s.withDepth;
      EXPECT_EQ(frame->depth.type(), CV_16UC1);
      EXPECT_EQ(frame->depth.size(), frame->left.size());
    }
    s.warnings += frame->warnings.size();
    ++s.frames;
  }
  std::vector<double> frameTimes, gtTimes;
  for (std::size_t i = 0; i < reader.size(); ++i) frameTimes.push_back(reader.timestamp(i));
  for (const auto& sp : reader.groundTruth()) gtTimes.push_back(sp.t);
  s.groundTruthMatched = orbis::associateTimestamps(frameTimes, gtTimes, 0.02).size();
  std::printf(
      "[ dataset  ] %s: %zu frames, %zu with right image, %zu with depth, %zu warnings, "
      "%zu ground-truth poses, %zu frames matched to ground truth\n",
      reader.root().filename().string().c_str(), s.frames, s.withRight, s.withDepth, s.warnings,
      reader.groundTruth().size(), s.groundTruthMatched);
  return s;
}

TEST(RealDatasets, TumTeddyAllFramesWithDepth) {
  ORBIS_REQUIRE_DATASET(root, "tum_fr3_teddy_200");
  const auto reader = orbis::openDataset(orbis::DatasetKind::TumRgbd, root);
  ASSERT_EQ(reader->sensor(), orbis::SensorKind::Rgbd);
  EXPECT_EQ(reader->size(), 200u);
  const ReadSummary s = readAll(*reader, CV_8UC3);
  EXPECT_EQ(s.frames, 200u);
  // Seven colour frames have their nearest depth map 29-32 ms away: reported, not dropped.
  EXPECT_EQ(s.withDepth, 193u);
  EXPECT_EQ(s.warnings, 7u);
  // The README: 195 of the 200 frames lie inside the ground truth's time span; one more frame,
  // 9 ms before its first pose, is within the 20 ms association window.
  EXPECT_EQ(s.groundTruthMatched, 196u);
  std::size_t inside = 0;
  for (std::size_t i = 0; i < reader->size(); ++i)
    inside += reader->timestamp(i) >= reader->groundTruth().front().t &&
              reader->timestamp(i) <= reader->groundTruth().back().t;
  std::printf("[ dataset  ] tum_fr3_teddy_200: %zu frames inside the ground-truth time span\n", inside);
  EXPECT_EQ(inside, 195u);

  const auto camera = std::get<orbis::RgbdCamera<double>>(reader->camera());
  EXPECT_DOUBLE_EQ(camera.pinhole.fx, 535.4);
  EXPECT_NEAR(camera.bf(), 40.0, 1e-9);  // ORB-SLAM2's Camera.bf for every Kinect
  EXPECT_DOUBLE_EQ(camera.disparitySigma, orbis::RgbdCamera<double>::kDefaultDisparitySigma);

  // Raw depth through the camera's factor: the Kinect sees the teddy scene between ~0.5 and ~5 m.
  const orbis::DatasetFrame f = reader->frame(100);
  double minDepth = 0, maxDepth = 0;
  cv::minMaxLoc(f.depth, &minDepth, &maxDepth);
  maxDepth = camera.metricDepth(maxDepth);
  EXPECT_EQ(minDepth, 0.0);  // holes stay 0
  EXPECT_GT(maxDepth, 1.0);
  EXPECT_LT(maxDepth, 10.0);
}

TEST(RealDatasets, TumTeddyDepthWindowIsConfigurable) {
  ORBIS_REQUIRE_DATASET(root, "tum_fr3_teddy_200");
  orbis::DatasetOptions options;
  options.maxDepthDt = 0.04;
  const auto reader = orbis::openDataset(orbis::DatasetKind::TumRgbd, root, options);
  // Frame 168's depth map is 29 ms away: paired at 40 ms. Frame 133's nearest depth map is
  // nearer still to frame 134, and pairing is one-to-one: still reported at 40 ms.
  EXPECT_FALSE(reader->frame(168).depth.empty());
  EXPECT_TRUE(reader->frame(168).warnings.empty());
  EXPECT_TRUE(reader->frame(133).depth.empty());
  EXPECT_EQ(reader->frame(133).warnings.size(), 1u);
  options.maxDepthDt = 0.02;
  options.strict = true;
  EXPECT_THROW(orbis::openDataset(orbis::DatasetKind::TumRgbd, root, options), orbis::Error);
}

TEST(RealDatasets, TumTeddyAsMonocular) {
  ORBIS_REQUIRE_DATASET(root, "tum_fr3_teddy_200");
  orbis::DatasetOptions options;
  options.sensor = orbis::SensorKind::Monocular;
  const auto reader = orbis::openDataset(orbis::DatasetKind::TumRgbd, root, options);
  const orbis::DatasetFrame f = reader->frame(0);
  EXPECT_TRUE(f.depth.empty());
  EXPECT_TRUE(std::holds_alternative<orbis::PinholeCamera<double>>(reader->camera()));
}

TEST(RealDatasets, EurocAllStereoPairsRectified) {
  ORBIS_REQUIRE_DATASET(root, "euroc_V1_01_easy_95");
  ASSERT_EQ(orbis::detectDatasetKind(root), orbis::DatasetKind::Euroc);
  const auto reader = orbis::openDataset(orbis::DatasetKind::Euroc, root);
  EXPECT_EQ(reader->size(), 95u);
  const ReadSummary s = readAll(*reader, CV_8UC1);
  EXPECT_EQ(s.frames, 95u);
  EXPECT_EQ(s.withRight, 95u);
  EXPECT_EQ(s.warnings, 0u);
  EXPECT_EQ(s.groundTruthMatched, 95u);

  const auto camera = std::get<orbis::RectifiedStereoCamera<double>>(reader->camera());
  EXPECT_NEAR(camera.baseline, 0.110, 0.002);  // the VI-sensor's ~11 cm baseline
  EXPECT_EQ(camera.pinhole.width, 752);
  EXPECT_GT(camera.pinhole.fx, 300.0);
}

TEST(RealDatasets, EurocGroundTruthIsTheLeftCameraPose) {
  ORBIS_REQUIRE_DATASET(root, "euroc_V1_01_easy_95");
  orbis::DatasetOptions options;
  options.rectify = false;
  options.sensor = orbis::SensorKind::Monocular;
  const auto reader = orbis::openDataset(orbis::DatasetKind::Euroc, root, options);
  const orbis::Trajectory body = orbis::readTrajectory(
      root / "mav0" / "state_groundtruth_estimate0" / "data.csv", orbis::TrajectoryFormat::Euroc);
  ASSERT_EQ(reader->groundTruth().size(), body.size());
  // cam0's T_BS translation, from its sensor.yaml.
  const Eigen::Vector3d bodyToCamera(-0.0216401454975, -0.064676986768, 0.00981073058949);
  for (std::size_t i = 0; i < body.size(); i += 17) {
    const Eigen::Vector3d expected = body[i].pose * bodyToCamera;
    EXPECT_LT((reader->groundTruth()[i].pose.translation() - expected).norm(), 1e-9);
  }
  // The camera looks roughly along the body's z axis (T_BS's third column).
  const Eigen::Vector3d opticalAxisInBody =
      body[0].pose.rotationMatrix().transpose() * reader->groundTruth()[0].pose.rotationMatrix().col(2);
  EXPECT_GT(opticalAxisInBody.z(), 0.99);
}

TEST(RealDatasets, EurocRectifiedGroundTruthKeepsTheCentreAndTurnsByTheRectification) {
  ORBIS_REQUIRE_DATASET(root, "euroc_V1_01_easy_95");
  orbis::DatasetOptions raw;
  raw.rectify = false;
  raw.sensor = orbis::SensorKind::Monocular;
  const auto unrectified = orbis::openDataset(orbis::DatasetKind::Euroc, root, raw);
  const auto rectified = orbis::openDataset(orbis::DatasetKind::Euroc, root);
  const auto& a = unrectified->groundTruth();
  const auto& b = rectified->groundTruth();
  ASSERT_EQ(a.size(), b.size());
  // The same rotation R1^T between the raw and the rectified left camera at every pose: small
  // (the VI-sensor is nearly rectified already) but not zero.
  const Eigen::Matrix3d rawFromRectified = a[0].pose.rotationMatrix().transpose() * b[0].pose.rotationMatrix();
  const double angle = Eigen::AngleAxisd(rawFromRectified).angle();
  EXPECT_GT(angle, 1e-4);
  EXPECT_LT(angle, 0.05);
  for (std::size_t i = 0; i < a.size(); i += 101) {
    EXPECT_LT((a[i].pose.translation() - b[i].pose.translation()).norm(), 1e-12);
    EXPECT_TRUE((a[i].pose.rotationMatrix().transpose() * b[i].pose.rotationMatrix()).isApprox(rawFromRectified, 1e-9));
  }
}

TEST(RealDatasets, KittiAllStereoPairs) {
  ORBIS_REQUIRE_DATASET(root, "kitti_06_first51");
  ASSERT_EQ(orbis::detectDatasetKind(root), orbis::DatasetKind::Kitti);
  const auto reader = orbis::openDataset(orbis::DatasetKind::Kitti, root);
  EXPECT_EQ(reader->size(), 51u);
  const ReadSummary s = readAll(*reader, CV_8UC1);
  EXPECT_EQ(s.frames, 51u);
  EXPECT_EQ(s.withRight, 51u);
  EXPECT_EQ(s.warnings, 0u);
  EXPECT_EQ(s.groundTruthMatched, 51u);

  const auto camera = std::get<orbis::RectifiedStereoCamera<double>>(reader->camera());
  EXPECT_NEAR(camera.baseline, 0.537, 0.001);
  EXPECT_NEAR(camera.bf(), 379.8145, 1e-3);
  EXPECT_EQ(camera.pinhole.width, 1226);
  EXPECT_EQ(camera.pinhole.height, 370);
  // The car drives about 60 m forward (camera z) in these 51 frames.
  const auto& gt = reader->groundTruth();
  EXPECT_NEAR(gt.back().pose.translation().z(), 60.0, 10.0);
}

}  // namespace
