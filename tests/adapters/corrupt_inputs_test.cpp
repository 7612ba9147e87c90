// Small datasets written to a temporary folder, then broken one way at a time: every error
// names the file (and line), and a missing right image or depth map is reported, not skipped.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include <unistd.h>

#include "orbis/adapters/dataset.hpp"
#include "orbis/util/error.hpp"

namespace {

namespace fs = std::filesystem;

class CorruptInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test and process: ctest runs the tests of this fixture in parallel.
    root_ = fs::temp_directory_path() /
            ("orbis_adapters_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  void writeText(const fs::path& relative, const std::string& text) {
    fs::create_directories((root_ / relative).parent_path());
    std::ofstream(root_ / relative) << text;
  }
  void writeImage(const fs::path& relative, int type) {
    fs::create_directories((root_ / relative).parent_path());
    cv::Mat image(48, 64, type, cv::Scalar::all(type == CV_16UC1 ? 5000 : 128));
    ASSERT_TRUE(cv::imwrite((root_ / relative).string(), image));
  }

  // A three-frame TUM sequence; depth listed for all three.
  void makeTum(int freiburg = 3) {
    std::string rgb = "# color images\n# file: 'rgbd_dataset_freiburg" + std::to_string(freiburg) + "_test.bag'\n",
                depth = "# depth\n";
    for (int i = 0; i < 3; ++i) {
      const std::string t = "100." + std::to_string(i) + "00000";
      rgb += t + " rgb/" + t + ".png\n";
      depth += t + "1 depth/" + t + "1.png\n";
      writeImage("rgb/" + t + ".png", CV_8UC3);
      writeImage("depth/" + t + "1.png", CV_16UC1);
    }
    writeText("rgb.txt", rgb);
    writeText("depth.txt", depth);
    writeText("groundtruth.txt", "# gt\n100.0 0 0 0 0 0 0 1\n100.1 0 0 1 0 0 0 1\n");
  }

  // A two-frame KITTI sequence with both cameras.
  void makeKitti() {
    const std::string p = " 700 0 600 0 0 700 180 0 0 0 1 0\n";
    writeText("sequences/00/calib.txt", "P0:" + p + "P1: 700 0 600 -350 0 700 180 0 0 0 1 0\n");
    writeText("sequences/00/times.txt", "0.0\n0.1\n");
    for (int i = 0; i < 2; ++i)
      for (int c = 0; c < 2; ++c)
        writeImage("sequences/00/image_" + std::to_string(c) + "/00000" + std::to_string(i) + ".png",
                   CV_8UC1);
  }

  // Expects an orbis::Error whose source is root_/file and whose location is `where`.
  template <class F>
  void expectError(F&& open, const fs::path& file, const std::string& where) {
    try {
      open();
      ADD_FAILURE() << "no error; expected one naming " << file << " " << where;
    } catch (const orbis::Error& e) {
      EXPECT_EQ(fs::path(e.source()), root_ / file) << e.what();
      EXPECT_EQ(e.where(), where) << e.what();
    }
  }

  fs::path root_;
};

TEST_F(CorruptInputs, IntactTumSequenceReadsCleanly) {
  makeTum();
  const auto reader = orbis::openTumRgbd(root_, {});
  ASSERT_EQ(reader->size(), 3u);
  const auto f = reader->frame(2);
  EXPECT_TRUE(f.warnings.empty());
  ASSERT_EQ(f.depth.type(), CV_16UC1);  // raw, as stored; the camera converts
  EXPECT_EQ(f.depth.at<std::uint16_t>(0, 0), 5000);
  EXPECT_EQ(std::get<orbis::RgbdCamera<double>>(reader->camera()).metricDepth(5000.0), 1.0);
  EXPECT_EQ(reader->groundTruth().size(), 2u);
}

// The Kinect comes from the list's header: its intrinsics, ORB-SLAM2's virtual bf of 40, and its
// depth factor (freiburg2's Kinect reads ~4 % long; ORB-SLAM2's TUM2.yaml uses 5208).
TEST_F(CorruptInputs, TumCameraFollowsTheKinect) {
  for (const int freiburg : {1, 2, 3}) {
    fs::remove_all(root_);
    fs::create_directories(root_);
    makeTum(freiburg);
    const auto camera = std::get<orbis::RgbdCamera<double>>(orbis::openTumRgbd(root_, {})->camera());
    EXPECT_NEAR(camera.bf(), 40.0, 1e-9) << "freiburg" << freiburg;
    EXPECT_DOUBLE_EQ(camera.depthScale, freiburg == 2 ? 5208.0 : 5000.0) << "freiburg" << freiburg;
  }
}

TEST_F(CorruptInputs, TumMalformedOutOfOrderAndMissingNameFileAndLine) {
  makeTum();
  writeText("rgb.txt", "# c\n100.0 rgb/100.000000.png\n100.1 rgb/100.100000.png extra\n");
  expectError([&] { orbis::openTumRgbd(root_, {}); }, "rgb.txt", "line 3");
  writeText("rgb.txt", "100.0 rgb/100.000000.png\nabc rgb/100.100000.png\n");
  expectError([&] { orbis::openTumRgbd(root_, {}); }, "rgb.txt", "line 2");
  writeText("rgb.txt", "100.0 rgb/100.000000.png\n100.5 rgb/nothere.png\n");
  expectError([&] { orbis::openTumRgbd(root_, {}); }, "rgb.txt", "line 2");
  fs::remove(root_ / "rgb.txt");
  expectError([&] { orbis::openTumRgbd(root_, {}); }, "rgb.txt", "");
}

TEST_F(CorruptInputs, TolerantReadingTurnsBadRowsIntoFrameErrorsAndWarnings) {
  makeTum();
  // Row 4 repeats row 3's timestamp (kept: row 3, as evo keeps the first); row 5 names an image
  // that is not there.
  writeText("rgb.txt",
            "# c\n# f\n100.000000 rgb/100.000000.png\n100.000000 rgb/100.100000.png\n"
            "100.100000 rgb/gone.png\n100.200000 rgb/100.200000.png\n");
  expectError([&] { orbis::openTumRgbd(root_, {}); }, "rgb.txt", "line 5");
  orbis::DatasetOptions tolerant;
  tolerant.tolerateBadFrames = true;
  const auto reader = orbis::openTumRgbd(root_, tolerant);
  ASSERT_EQ(reader->size(), 3u);
  ASSERT_EQ(reader->warnings().size(), 1u);
  EXPECT_NE(reader->warnings()[0].find("rgb.txt: 1 row(s) repeat an earlier timestamp (first at line 4)"),
            std::string::npos)
      << reader->warnings()[0];
  EXPECT_NO_THROW(reader->frame(0));
  expectError([&] { reader->frame(1); }, "rgb.txt", "line 5");
  EXPECT_NO_THROW(reader->frame(2));
}

// Lists as published may come out of order: sorted, with one warning naming the first such row.
TEST_F(CorruptInputs, TumListOutOfOrderIsSorted) {
  makeTum();
  writeText("rgb.txt", "100.100000 rgb/100.100000.png\n100.000000 rgb/100.000000.png\n");
  const auto reader = orbis::openTumRgbd(root_, {});
  ASSERT_EQ(reader->size(), 2u);
  EXPECT_LT(reader->timestamp(0), reader->timestamp(1));
  ASSERT_EQ(reader->warnings().size(), 1u);
  EXPECT_NE(reader->warnings()[0].find("(first at line 2); rows sorted"), std::string::npos) << reader->warnings()[0];
}

// An rgb-only folder is refused when opened, saying so, not skipped frame by frame.
TEST_F(CorruptInputs, TumWithoutDepthIsRefusedAtOnce) {
  makeTum();
  for (const std::string& depthList : {std::string("# depth\n"), std::string("100.5 depth/none.png\n"), std::string()}) {
    if (depthList.empty()) fs::remove(root_ / "depth.txt");
    else writeText("depth.txt", depthList);
    try {
      orbis::openTumRgbd(root_, {});
      ADD_FAILURE() << "no error for depth.txt '" << depthList << "'";
    } catch (const orbis::Error& e) {
      EXPECT_EQ(fs::path(e.source()), root_);
      EXPECT_NE(std::string(e.what()).find("no depth maps"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--sensor mono"), std::string::npos) << e.what();
    }
    orbis::DatasetOptions mono;
    mono.sensor = orbis::SensorKind::Monocular;
    EXPECT_EQ(orbis::openTumRgbd(root_, mono)->size(), 3u);
  }
}

TEST_F(CorruptInputs, TumGroundTruthErrorsNameTheLine) {
  makeTum();
  writeText("groundtruth.txt", "# gt\n100.0 0 0 0 0 0 0 1\n100.1 0 0 1 0 0 1\n");
  expectError([&] { orbis::openTumRgbd(root_, {}); }, "groundtruth.txt", "line 3");
}

TEST_F(CorruptInputs, TumUnreadableImageNamesFileAndLine) {
  makeTum();
  writeText("rgb/100.100000.png", "this is not a PNG");
  const auto reader = orbis::openTumRgbd(root_, {});
  expectError([&] { reader->frame(1); }, "rgb.txt", "line 4");
  EXPECT_NO_THROW(reader->frame(0));
}

TEST_F(CorruptInputs, TumMissingDepthIsAWarningOrAStrictError) {
  makeTum();
  fs::remove(root_ / "depth/100.1000001.png");
  const auto reader = orbis::openTumRgbd(root_, {});
  const auto f = reader->frame(1);
  EXPECT_TRUE(f.depth.empty());
  ASSERT_EQ(f.warnings.size(), 1u);
  EXPECT_NE(f.warnings[0].find("depth.txt, line 3"), std::string::npos) << f.warnings[0];
  EXPECT_TRUE(reader->frame(0).warnings.empty());

  orbis::DatasetOptions strict;
  strict.strict = true;
  expectError([&] { orbis::openTumRgbd(root_, strict); }, "depth.txt", "line 3");

  // A depth map too far in time from its colour image is missing too.
  writeText("depth.txt", "100.0000001 depth/100.0000001.png\n100.2000001 depth/100.2000001.png\n");
  const auto sparse = orbis::openTumRgbd(root_, {});
  EXPECT_EQ(sparse->frame(1).warnings.size(), 1u);
  expectError([&] { orbis::openTumRgbd(root_, strict); }, "rgb.txt", "line 4");
}

TEST_F(CorruptInputs, KittiErrorsNameFileAndLineOrKey) {
  makeKitti();
  const auto intact = orbis::openKitti(root_, {});
  EXPECT_EQ(intact->size(), 2u);
  EXPECT_NEAR(std::get<orbis::RectifiedStereoCamera<double>>(intact->camera()).baseline, 0.5, 1e-12);

  writeText("sequences/00/times.txt", "0.1\n0.0\n");
  expectError([&] { orbis::openKitti(root_, {}); }, "sequences/00/times.txt", "line 2");
  writeText("sequences/00/times.txt", "0.0\n0.1\n0.2\n");  // a third frame without images
  expectError([&] { orbis::openKitti(root_, {}); }, "sequences/00/times.txt", "line 3");
  writeText("sequences/00/times.txt", "0.0\n0.1\n");

  writeText("sequences/00/calib.txt", "P0: 700 0 600 0 0 700 180 0 0 0 1 0\n");
  expectError([&] { orbis::openKitti(root_, {}); }, "sequences/00/calib.txt", "key P1");
  writeText("sequences/00/calib.txt", "P0: 700 0 600 0 0 700 180 0 0 0 1\nP1: 1 2\n");
  expectError([&] { orbis::openKitti(root_, {}); }, "sequences/00/calib.txt", "line 1");
  makeKitti();

  writeText("poses/00.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 x\n");
  expectError([&] { orbis::openKitti(root_, {}); }, "poses/00.txt", "line 2");
  writeText("poses/00.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");  // one pose for two frames
  expectError([&] { orbis::openKitti(root_, {}); }, "sequences/00/times.txt", "");
}

// calib.txt as the odometry benchmark ships it: P0-P3 and the velodyne's Tr; times in e-notation.
TEST_F(CorruptInputs, KittiFullOdometryCalibrationIsRead) {
  makeKitti();
  writeText("sequences/00/calib.txt",
            "P0: 7.188560e+02 0 6.071928e+02 0 0 7.188560e+02 1.852157e+02 0 0 0 1 0\n"
            "P1: 7.188560e+02 0 6.071928e+02 -3.861448e+02 0 7.188560e+02 1.852157e+02 0 0 0 1 0\n"
            "P2: 7.188560e+02 0 6.071928e+02 4.538225e+01 0 7.188560e+02 1.852157e+02 -1.130887e-01 0 0 1 3.779761e-03\n"
            "P3: 7.188560e+02 0 6.071928e+02 -3.372877e+02 0 7.188560e+02 1.852157e+02 2.369057e+00 0 0 1 4.915215e-03\n"
            "Tr: 4.276802e-04 -9.999672e-01 -8.084491e-03 -1.198459e-02 -7.210626e-03 8.081198e-03 "
            "-9.999413e-01 -5.403984e-02 9.999738e-01 4.859485e-04 -7.206933e-03 -2.921968e-01\n");
  writeText("sequences/00/times.txt", "0.000000e+00\n1.036223e-01\n");
  const auto reader = orbis::openKitti(root_, {});
  const auto camera = std::get<orbis::RectifiedStereoCamera<double>>(reader->camera());
  EXPECT_DOUBLE_EQ(camera.pinhole.fx, 718.856);
  EXPECT_NEAR(camera.bf(), 386.1448, 1e-9);
  EXPECT_DOUBLE_EQ(reader->timestamp(1), 0.1036223);
}

TEST_F(CorruptInputs, KittiMissingRightImageIsReported) {
  makeKitti();
  fs::remove(root_ / "sequences/00/image_1/000001.png");
  const auto reader = orbis::openKitti(root_ / "sequences" / "00", {});
  const auto f = reader->frame(1);
  EXPECT_TRUE(f.right.empty());
  ASSERT_EQ(f.warnings.size(), 1u);
  EXPECT_NE(f.warnings[0].find("000001.png"), std::string::npos);
  orbis::DatasetOptions strict;
  strict.strict = true;
  expectError([&] { orbis::openKitti(root_, strict); }, "sequences/00/times.txt", "line 2");
}

TEST_F(CorruptInputs, EurocErrorsNameFileAndLine) {
  writeText("mav0/cam0/data.csv", "#timestamp [ns],filename\n1000000000,a.png\nten,b.png\n");
  writeImage("mav0/cam0/data/a.png", CV_8UC1);
  writeImage("mav0/cam0/data/b.png", CV_8UC1);
  expectError([&] { orbis::openEuroc(root_, {}); }, "mav0/cam0/data.csv", "line 3");
  writeText("mav0/cam0/data.csv", "#timestamp [ns],filename\n1000000000,a.png\n1.5e9,b.png\n");
  expectError([&] { orbis::openEuroc(root_, {}); }, "mav0/cam0/data.csv", "line 3");
  writeText("mav0/cam0/data.csv", "#timestamp [ns],filename\n1000000000,a.png\n1050000000,b.png\n");
  expectError([&] { orbis::openEuroc(root_, {}); }, "mav0/cam0/sensor.yaml", "");
}

TEST(DatasetNames, ParseAndDetect) {
  EXPECT_EQ(orbis::parseDatasetKind("euroc"), orbis::DatasetKind::Euroc);
  EXPECT_EQ(orbis::parseSensorKind("mono"), orbis::SensorKind::Monocular);
  EXPECT_THROW(orbis::parseDatasetKind("bonn"), orbis::Error);
  EXPECT_THROW(orbis::parseSensorKind("lidar"), orbis::Error);
  EXPECT_FALSE(orbis::detectDatasetKind(fs::temp_directory_path() / "orbis_no_such_dataset").has_value());
}

}  // namespace
