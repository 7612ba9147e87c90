// A KITTI raw drive synthesised from a rendered KITTI-layout sequence: images renamed into
// image_00/data and image_01/data, date-time timestamps, calib_*.txt with non-trivial
// rectification and sensor transforms, and the ground truth written as OXTS packets (GPS
// latitude/longitude/altitude and roll/pitch/yaw). The reader must give back the rendered
// camera poses, and SLAM must run on the drive.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "orbis/adapters/dataset.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/system/dataset_runner.hpp"
#include "orbis/util/error.hpp"
#include "rendered_sequence.hpp"

namespace {

namespace fs = std::filesystem;
using Isometry = Eigen::Isometry3d;

constexpr double kEarthRadius = 6378137.0, kDegree = M_PI / 180.0;
constexpr double kLatitude = 49.011, kLongitude = 8.4242, kAltitude = 112.5;

Isometry rigid(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Isometry pose = Isometry::Identity();
  pose.linear() = r;
  pose.translation() = t;
  return pose;
}

Eigen::Matrix3d rotation(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::string numbers(const Eigen::MatrixXd& m) {
  std::string out;
  char buf[40];
  for (int r = 0; r < m.rows(); ++r)
    for (int c = 0; c < m.cols(); ++c) {
      std::snprintf(buf, sizeof buf, " %.17g", m(r, c));
      out += buf;
    }
  return out;
}

// Sensor transforms of the shape KITTI publishes (velodyne x forward, camera z forward).
const Eigen::Matrix3d kRectFromCam = rotation(0.004, -0.007, 0.01);
const Isometry kCamFromVelo = rigid((Eigen::Matrix3d() << 0, -1, 0, 0, 0, -1, 1, 0, 0).finished() * rotation(0.002, 0.01, -0.003),
                                    {-0.0027, -0.076, -0.272});
const Isometry kVeloFromImu = rigid(rotation(0.001, -0.002, 0.003), {-0.81, 0.32, -0.80});
const Isometry kRectFromImu = rigid(kRectFromCam, Eigen::Vector3d::Zero()) * kCamFromVelo * kVeloFromImu;

std::string dateTime(double seconds) {  // 2011-09-26 13:02:SS.fffffffff
  char buf[64];
  std::snprintf(buf, sizeof buf, "2011-09-26 13:%02d:%012.9f", static_cast<int>(seconds / 60), std::fmod(seconds, 60.0));
  return buf;
}

// The OXTS packet of an IMU pose in the Mercator frame scaled at kLatitude (inverse of the
// devkit's convertOxtsToPose).
std::string oxtsPacket(const Isometry& mercatorFromImu) {
  const double scale = std::cos(kLatitude * kDegree);
  const Eigen::Vector3d t = mercatorFromImu.translation();
  const double longitude = t.x() / (scale * kEarthRadius) / kDegree;
  const double latitude = 2.0 * std::atan(std::exp(t.y() / (scale * kEarthRadius))) / kDegree - 90.0;
  const Eigen::Matrix3d r = mercatorFromImu.linear();
  const double pitch = -std::asin(r(2, 0)), roll = std::atan2(r(2, 1), r(2, 2)), yaw = std::atan2(r(1, 0), r(0, 0));
  Eigen::VectorXd packet = Eigen::VectorXd::Zero(30);
  packet.head<6>() << latitude, longitude, t.z(), roll, pitch, yaw;
  return numbers(packet.transpose()).substr(1) + "\n";
}

class KittiRaw : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("orbis_kitti_raw_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    drive_ = root_ / "2011_09_26" / "2011_09_26_drive_0001_sync";
  }
  void TearDown() override { fs::remove_all(root_); }

  void write(const fs::path& file, const std::string& text) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
  }

  // Renders a small loop in the KITTI odometry layout and rearranges it.
  void makeDrive() {
    constexpr double fx = 250.0, width = 320, height = 240, baseline = 0.3;
    const fs::path odometry = root_ / "odometry";
    const auto written = orbis::test::renderSmallLoop(orbis::synth::SynthLayout::Kitti, odometry, 9, baseline);
    const fs::path sequenceDir = odometry / "sequences" / "00";
    const std::vector<double> times = orbis::readTimestamps(sequenceDir / "times.txt");
    renderedPoses_ = orbis::readTrajectory(written.groundTruth, orbis::TrajectoryFormat::Kitti, sequenceDir / "times.txt");

    std::string stamps, oxtsStamps;
    // The first packet lies at kLatitude, where the reader scales its Mercator frame.
    const double scale = std::cos(kLatitude * kDegree);
    const Isometry mercatorFromFirstImu =
        rigid(rotation(0.02, -0.01, 1.2),
              {scale * kLongitude * kDegree * kEarthRadius,
               scale * kEarthRadius * std::log(std::tan((90.0 + kLatitude) * kDegree / 2.0)), kAltitude});
    for (std::size_t i = 0; i < times.size(); ++i) {
      char image[32], packet[32];
      std::snprintf(image, sizeof image, "%06zu.png", i);
      std::snprintf(packet, sizeof packet, "%010zu", i);
      for (const char* camera : {"0", "1"}) {
        const fs::path target = drive_ / (std::string("image_0") + camera) / "data" / (std::string(packet) + ".png");
        fs::create_directories(target.parent_path());
        fs::rename(sequenceDir / (std::string("image_") + camera) / image, target);
      }
      stamps += dateTime(120.0 + times[i]) + "\n";
      oxtsStamps += dateTime(120.0 + times[i] + 0.004) + "\n";
      const Isometry firstCameraFromCamera = (toIsometry(renderedPoses_[0].pose).inverse() * toIsometry(renderedPoses_[i].pose));
      const Isometry firstImuFromImu = kRectFromImu.inverse() * firstCameraFromCamera * kRectFromImu;
      write(drive_ / "oxts" / "data" / (std::string(packet) + ".txt"), oxtsPacket(mercatorFromFirstImu * firstImuFromImu));
    }
    write(drive_ / "image_00" / "timestamps.txt", stamps);
    write(drive_ / "image_01" / "timestamps.txt", stamps);
    write(drive_ / "oxts" / "timestamps.txt", oxtsStamps);

    const fs::path date = drive_.parent_path();
    const double cx = width / 2.0, cy = height / 2.0;
    write(date / "calib_cam_to_cam.txt",
          "calib_time: 09-Jan-2012 13:57:47\ncorner_dist: 9.950000e-02\nS_rect_00: 3.200000e+02 2.400000e+02\n"
          "R_rect_00:" + numbers(kRectFromCam) + "\nP_rect_00:" +
              numbers((Eigen::Matrix<double, 3, 4>() << fx, 0, cx, 0, 0, fx, cy, 0, 0, 0, 1, 0).finished()) +
              "\nP_rect_01:" +
              numbers((Eigen::Matrix<double, 3, 4>() << fx, 0, cx, -fx * baseline, 0, fx, cy, 0, 0, 0, 1, 0).finished()) +
              "\n");
    write(date / "calib_velo_to_cam.txt", "calib_time: 15-Mar-2012 11:37:16\nR:" + numbers(kCamFromVelo.linear()) +
                                              "\nT:" + numbers(kCamFromVelo.translation().transpose()) +
                                              "\ndelta_f: 0 0\ndelta_c: 0 0\n");
    write(date / "calib_imu_to_velo.txt", "calib_time: 25-May-2012 16:47:16\nR:" + numbers(kVeloFromImu.linear()) +
                                              "\nT:" + numbers(kVeloFromImu.translation().transpose()) + "\n");
    fs::remove_all(odometry);
  }

  static Isometry toIsometry(const orbis::SE3d& pose) { return Isometry(pose.matrix()); }

  fs::path root_, drive_;
  orbis::Trajectory renderedPoses_;
};

TEST_F(KittiRaw, OxtsBecomeTheRenderedCameraPosesAndSlamRuns) {
  makeDrive();
  EXPECT_EQ(orbis::detectDatasetKind(drive_), orbis::DatasetKind::KittiRaw);
  const auto reader = orbis::openDataset(orbis::parseDatasetKind("kitti-raw"), drive_, {});
  ASSERT_EQ(reader->size(), 150u);
  EXPECT_NEAR(reader->timestamp(1) - reader->timestamp(0), renderedPoses_[1].t - renderedPoses_[0].t, 1e-6);
  const auto camera = std::get<orbis::RectifiedStereoCamera<double>>(reader->camera());
  EXPECT_DOUBLE_EQ(camera.pinhole.fx, 250.0);
  EXPECT_NEAR(camera.baseline, 0.3, 1e-12);
  EXPECT_EQ(camera.pinhole.width, 320);

  const orbis::Trajectory& truth = reader->groundTruth();
  ASSERT_EQ(truth.size(), renderedPoses_.size());
  const orbis::SE3d firstInverse = renderedPoses_[0].pose.inverse();
  for (std::size_t i = 0; i < truth.size(); i += 7) {
    const orbis::SE3d expected = firstInverse * renderedPoses_[i].pose;
    EXPECT_LT((truth[i].pose.translation() - expected.translation()).norm(), 1e-6) << "pose " << i;
    EXPECT_LT((truth[i].pose.so3().inverse() * expected.so3()).log().norm(), 1e-9) << "pose " << i;
    EXPECT_NEAR(truth[i].t - reader->timestamp(i), 0.004, 1e-6) << "pose " << i;
  }

  orbis::RunOptions options;
  options.vocabulary = orbis::defaultVocabularyPath();
  options.outDir = root_ / "out";
  options.deterministic = true;
  options.progress = false;
  options.maxFrames = 30;
  const orbis::RunReport report = orbis::runDataset(*reader, options);
  EXPECT_EQ(report.stats.tracked, 30u);
  ASSERT_TRUE(report.ateRmse.has_value());
  EXPECT_LT(*report.ateRmse, 0.05);
}

TEST_F(KittiRaw, BrokenFilesNameFileAndLineOrKey) {
  write(drive_ / "image_00" / "timestamps.txt", "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.06\n");
  EXPECT_THROW(orbis::openKittiRaw(drive_, {}), orbis::Error);  // no images
  for (const char* camera : {"image_00", "image_01"})
    for (const char* name : {"0000000000.png", "0000000001.png"}) {
      fs::create_directories(drive_ / camera / "data");
      std::ofstream(drive_ / camera / "data" / name, std::ios::binary);
    }
  auto expectError = [&](const fs::path& source, const std::string& where) {
    try {
      orbis::openKittiRaw(drive_, {});
      ADD_FAILURE() << "no error; expected one naming " << source << " " << where;
    } catch (const orbis::Error& e) {
      EXPECT_EQ(fs::path(e.source()).filename(), source.filename()) << e.what();
      EXPECT_EQ(e.where(), where) << e.what();
    }
  };
  write(drive_ / "image_00" / "timestamps.txt", "2011-09-26 13:02:25.964389445\n2011-09-26 25:02:26.06\n");
  expectError(drive_ / "image_00" / "timestamps.txt", "line 2");
  write(drive_ / "image_00" / "timestamps.txt", "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:25.9\n");
  expectError(drive_ / "image_00" / "timestamps.txt", "line 2");
  write(drive_ / "image_00" / "timestamps.txt", "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.06\n");
  expectError(drive_ / "image_00" / "timestamps.txt", "line 1");  // frame 0's PNG is empty
  for (const char* camera : {"image_00", "image_01"})
    for (const char* name : {"0000000000.png", "0000000001.png"})
      ASSERT_TRUE(cv::imwrite((drive_ / camera / "data" / name).string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(9))));
  expectError(drive_.parent_path() / "calib_cam_to_cam.txt", "");
  write(drive_.parent_path() / "calib_cam_to_cam.txt", "calib_time: 09-Jan-2012 13:57:47\nP_rect_00: 7 0 3 0 0 7 2 0 0 0 1 0\n");
  expectError(drive_.parent_path() / "calib_cam_to_cam.txt", "key P_rect_01");
  write(drive_.parent_path() / "calib_cam_to_cam.txt",
        "P_rect_00: 7 0 3 0 0 7 2 0 0 0 1 0\nP_rect_01: 7 0 3 -3.5 0 7 2 0 0 0 1 0\n");
  const auto reader = orbis::openKittiRaw(drive_, {});
  EXPECT_NEAR(std::get<orbis::RectifiedStereoCamera<double>>(reader->camera()).baseline, 0.5, 1e-12);
  EXPECT_TRUE(reader->groundTruth().empty());  // no oxts/
  write(drive_ / "oxts" / "timestamps.txt", "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.06\n");
  write(drive_ / "oxts" / "data" / "0000000000.txt", "49 8 100 0 0 0\n");
  EXPECT_EQ(orbis::openKittiRaw(drive_, {})->warnings().size(), 1u);  // calib_imu_to_velo.txt missing
}

}  // namespace
