// Trajectory I/O: round trips through every format, and errors that name file and line.
#include "orbis/io/trajectory.hpp"

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "orbis/util/error.hpp"

namespace {

namespace fs = std::filesystem;
using orbis::Trajectory;
using orbis::TrajectoryFormat;

class TrajectoryIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("orbis_traj_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
  fs::path dir_;
};

Trajectory randomTrajectory(std::size_t n, unsigned seed, double t0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Trajectory traj;
  for (std::size_t i = 0; i < n; ++i) {
    orbis::SE3d::Tangent xi;
    for (int k = 0; k < 6; ++k) xi[k] = normal(rng);
    traj.push_back({t0 + 0.05 * static_cast<double>(i) + 0.001 * std::abs(normal(rng)),
                    orbis::SE3d::exp(xi)});
  }
  return traj;
}

void expectSamePoses(const Trajectory& a, const Trajectory& b, double timeTolerance) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i].t, b[i].t, timeTolerance) << "pose " << i;
    EXPECT_LT((a[i].pose.matrix() - b[i].pose.matrix()).cwiseAbs().maxCoeff(), 1e-7) << "pose " << i;
  }
}

TEST_F(TrajectoryIoTest, TumAndEurocRoundTrip) {
  // Present-day epochs, where a double keeps ~0.2 microseconds.
  for (const auto& [format, name, t0] : {std::tuple{TrajectoryFormat::Tum, "traj.txt", 1305031102.160407},
                                         std::tuple{TrajectoryFormat::Euroc, "traj.csv", 1403715273.262142976}}) {
    const Trajectory original = randomTrajectory(50, format == TrajectoryFormat::Tum ? 1 : 2, t0);
    const fs::path p = dir_ / name;
    orbis::writeTrajectory(p, original, format);
    EXPECT_EQ(orbis::detectTrajectoryFormat(p), format);
    expectSamePoses(original, orbis::readTrajectory(p, format), 1e-6);
  }
}

TEST_F(TrajectoryIoTest, KittiRoundTripWithAndWithoutTimes) {
  const Trajectory original = randomTrajectory(30, 3, 0.0);
  const fs::path p = dir_ / "poses.txt";
  orbis::writeTrajectory(p, original, TrajectoryFormat::Kitti);
  EXPECT_EQ(orbis::detectTrajectoryFormat(p), TrajectoryFormat::Kitti);
  const Trajectory byIndex = orbis::readTrajectory(p, TrajectoryFormat::Kitti);
  ASSERT_EQ(byIndex.size(), original.size());
  for (std::size_t i = 0; i < byIndex.size(); ++i) EXPECT_EQ(byIndex[i].t, static_cast<double>(i));

  std::string times;
  for (const auto& sp : original) times += std::to_string(sp.t) + "\n";
  const fs::path timesFile = write("times.txt", times);
  expectSamePoses(original, orbis::readTrajectory(p, TrajectoryFormat::Kitti, timesFile), 1e-6);
}

TEST_F(TrajectoryIoTest, ReadsEurocGroundTruthWithExtraColumnsAndNormalisesQuaternions) {
  const fs::path p = write("gt.csv",
                           "#time(ns),px,py,pz,qw,qx,qy,qz,vx,vy,vz\n"
                           "1403715273262142976,1,2,3,2,0,0,0,9,9,9\n"
                           "1403715273312143104, 4, 5, 6, 0, 0, 0, 3\n");
  const Trajectory traj = orbis::readTrajectory(p, TrajectoryFormat::Euroc);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_NEAR(traj[1].t - traj[0].t, 0.050000128, 1e-6);
  EXPECT_TRUE(traj[0].pose.rotationMatrix().isIdentity(1e-12));
  EXPECT_NEAR(traj[1].pose.so3().unitQuaternion().z(), 1.0, 1e-12);  // qz=3 normalised
  EXPECT_EQ(traj[1].pose.translation(), Eigen::Vector3d(4, 5, 6));
}

// Every malformed input names the file and the offending line.
void expectLineError(const fs::path& p, TrajectoryFormat format, std::size_t line) {
  try {
    orbis::readTrajectory(p, format);
    ADD_FAILURE() << "no error for " << p;
  } catch (const orbis::Error& e) {
    EXPECT_EQ(e.source(), p.string());
    EXPECT_EQ(e.where(), "line " + std::to_string(line)) << e.what();
  }
}

TEST_F(TrajectoryIoTest, MalformedLinesNameFileAndLine) {
  expectLineError(write("short.txt", "# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n"), TrajectoryFormat::Tum, 3);
  expectLineError(write("word.txt", "1 0 0 0 0 0 0 1\n\n2 0 zero 0 0 0 0 1\n"), TrajectoryFormat::Tum, 3);
  expectLineError(write("nan.txt", "1 0 0 nan 0 0 0 1\n"), TrajectoryFormat::Tum, 1);
  expectLineError(write("zeroq.txt", "1 0 0 0 0 0 0 0\n"), TrajectoryFormat::Tum, 1);
  expectLineError(write("bad.csv", "#h\n100,1,2,3,1,0,0,0\n200,1,2,3,1,0,0\n"), TrajectoryFormat::Euroc, 3);
  expectLineError(write("float.csv", "1.5e9,1,2,3,1,0,0,0\n"), TrajectoryFormat::Euroc, 1);
  expectLineError(write("k.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n"), TrajectoryFormat::Kitti, 2);
  expectLineError(write("notrot.txt", "2 0 0 0 0 2 0 0 0 0 2 0\n"), TrajectoryFormat::Kitti, 1);
}

// TUM fr2/desk's ground truth repeats a timestamp (line 10,863): the first row is kept and the
// repair is one warning with its count, as evo does; rows out of order are sorted.
TEST_F(TrajectoryIoTest, RepeatedTimestampsKeepTheFirstAndOutOfOrderRowsAreSorted) {
  const fs::path gt = write("groundtruth.txt",
                            "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
                            "1311868164.3633 1 0 0 0 0 0 1\n"
                            "1311868164.3733 2 0 0 0 0 0 1\n"
                            "1311868164.3733 9 0 0 0 0 0 1\n"
                            "1311868164.3733 9 0 0 0 0 0 1\n"
                            "1311868164.3833 3 0 0 0 0 0 1\n");
  std::vector<std::string> warnings;
  const Trajectory traj = orbis::readTrajectory(gt, TrajectoryFormat::Tum, {}, &warnings);
  ASSERT_EQ(traj.size(), 3u);
  EXPECT_EQ(traj[1].pose.translation().x(), 2.0);  // the first of the repeats
  EXPECT_EQ(traj[2].pose.translation().x(), 3.0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(gt.string() + ": 2 row(s) repeat"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("line 5"), std::string::npos) << warnings[0];

  const fs::path shuffled = write("order.csv", "#h\n300,3,0,0,1,0,0,0\n100,1,0,0,1,0,0,0\n200,2,0,0,1,0,0,0\n"
                                               "100,7,0,0,1,0,0,0\n");
  warnings.clear();
  const Trajectory sorted = orbis::readTrajectory(shuffled, TrajectoryFormat::Euroc, {}, &warnings);
  ASSERT_EQ(sorted.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(sorted[i].pose.translation().x(), static_cast<double>(i + 1));
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("2 row(s) earlier than the row before (first at line 3)"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("1 row(s) repeat an earlier timestamp (first at line 5)"), std::string::npos)
      << warnings[1];
}

TEST(TimeOrder, SortsStablyAndDropsLaterRepeats) {
  const orbis::TimeOrder order = orbis::putInTimeOrder({1.0, 3.0, 2.0, 3.0, 1.0}, {10, 11, 12, 13, 14});
  EXPECT_EQ(order.keep, (std::vector<std::size_t>{0, 2, 1}));
  EXPECT_EQ(order.repeated, 2u);
  EXPECT_EQ(order.firstRepeatedLine, 13u);
  EXPECT_EQ(order.outOfOrder, 2u);
  EXPECT_EQ(order.firstOutOfOrderLine, 12u);
  EXPECT_TRUE(orbis::putInTimeOrder({1.0, 2.0}, {1, 2}).warnings("f").empty());
}

TEST_F(TrajectoryIoTest, DetectsEurocAndTumFormsWhateverTheExtension) {
  EXPECT_EQ(orbis::detectTrajectoryFormat(write("gt.txt", "#h\n1403715273262142976,1,2,3,1,0,0,0,9,9\n")),
            TrajectoryFormat::Euroc);
  EXPECT_EQ(orbis::detectTrajectoryFormat(write("gt.csv", "# t x\n1403715274.30214 0 0 0 0 0 0 1\n")),
            TrajectoryFormat::Tum);
  EXPECT_EQ(orbis::detectTrajectoryFormat(write("data.tum", "1403715274.30214 0 0 0 0 0 0 1\n")),
            TrajectoryFormat::Tum);
  EXPECT_THROW(orbis::detectTrajectoryFormat(write("odd.txt", "1 2 3\n")), orbis::Error);
}

TEST_F(TrajectoryIoTest, MissingFilesAndMismatchedTimesAreErrors) {
  EXPECT_THROW(orbis::readTrajectory(dir_ / "absent.txt", TrajectoryFormat::Tum), orbis::Error);
  const fs::path poses = write("poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  const fs::path times = write("times.txt", "0.0\n");
  try {
    orbis::readTrajectory(poses, TrajectoryFormat::Kitti, times);
    ADD_FAILURE() << "no error for a times file of the wrong length";
  } catch (const orbis::Error& e) {
    EXPECT_EQ(e.source(), times.string());
  }
  EXPECT_THROW(orbis::writeTrajectory(dir_ / "no_such_dir" / "x.txt", {}, TrajectoryFormat::Tum),
               orbis::Error);
  EXPECT_THROW(orbis::parseTrajectoryFormat("ply"), orbis::Error);
}

TEST(TrajectorySpan, PosesCoveringKeepsTheSpanPlusMargin) {
  Trajectory gt;
  for (int i = 0; i < 10; ++i) gt.push_back({static_cast<double>(i), orbis::SE3d()});
  const Trajectory estimate{{3.2, orbis::SE3d()}, {5.0, orbis::SE3d()}};
  const Trajectory covered = orbis::posesCovering(gt, estimate, 1.0);
  ASSERT_EQ(covered.size(), 4u);  // 2.2 .. 6.0 holds 3, 4, 5, 6
  EXPECT_EQ(covered.front().t, 3.0);
  EXPECT_EQ(covered.back().t, 6.0);
  EXPECT_EQ(orbis::posesCovering(gt, {}, 1.0).size(), gt.size());
}

}  // namespace
