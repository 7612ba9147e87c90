// Evaluation plots: both renderers draw the trajectories where the data puts them.
#include "orbis/eval/plot.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include <unistd.h>

#include "orbis/util/error.hpp"

namespace {

namespace fs = std::filesystem;

orbis::eval::EvaluationPlot circlePlot() {
  orbis::eval::EvaluationPlot plot;
  plot.title = "test <&> plot";
  for (int i = 0; i <= 100; ++i) {
    const double a = 2 * M_PI * i / 100.0;
    // A circle in the x-z plane (y nearly constant): the top view must pick x and z.
    plot.groundTruth.push_back(
        {0.1 * i,
         orbis::SE3d(orbis::SO3d(), Eigen::Vector3d(std::cos(a), 0.01 * std::sin(3 * a), std::sin(a)))});
    plot.estimate.push_back(
        {0.1 * i, orbis::SE3d(orbis::SO3d(), Eigen::Vector3d(1.1 * std::cos(a), 0, 1.1 * std::sin(a)))});
    plot.errorTimes.push_back(0.1 * i);
    plot.errors.push_back(0.1);
  }
  return plot;
}

class PlotTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test and process: ctest runs the tests of this fixture in parallel.
    dir_ = fs::temp_directory_path() /
           ("orbis_plot_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(PlotTest, PngShowsBothTrajectoriesInTheirColours) {
  const fs::path file = dir_ / "plot.png";
  orbis::eval::writeEvaluationPlot(file, circlePlot());
  const cv::Mat image = cv::imread(file.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1400);
  EXPECT_EQ(image.rows, 700);
  // Count strongly blue (estimate) and red (error curve) pixels; a blank or one-line picture fails.
  int blue = 0, red = 0;
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c) {
      const cv::Vec3b p = image.at<cv::Vec3b>(r, c);
      if (p[0] > 150 && p[2] < 80) ++blue;
      if (p[2] > 180 && p[0] < 80 && p[1] < 80) ++red;
    }
  EXPECT_GT(blue, 1000);  // the circle, 2 px wide and ~1600 px round
  EXPECT_GT(red, 300);    // a flat error line across the right panel
  // The estimate circle lies in the left panel only; the error curve in the right one.
  int blueRight = 0;
  for (int r = 0; r < image.rows; ++r)
    for (int c = 700; c < image.cols; ++c) {
      const cv::Vec3b p = image.at<cv::Vec3b>(r, c);
      if (p[0] > 150 && p[2] < 80) ++blueRight;
    }
  EXPECT_EQ(blueRight, 0);
}

TEST_F(PlotTest, SvgIsWellFormedTextWithEscapedTitleAndTopViewAxes) {
  const fs::path file = dir_ / "plot.svg";
  orbis::eval::writeEvaluationPlot(file, circlePlot());
  std::stringstream text;
  text << std::ifstream(file).rdbuf();
  const std::string svg = text.str();
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("test &lt;&amp;&gt; plot"), std::string::npos);
  EXPECT_NE(svg.find(">x [m]<"), std::string::npos);
  EXPECT_NE(svg.find(">z [m]<"), std::string::npos);
  EXPECT_EQ(svg.find(">y [m]<"), std::string::npos);
  EXPECT_GE(std::count(svg.begin(), svg.end(), '<'), 30);
}

TEST_F(PlotTest, UnknownExtensionOrUnwritablePathIsAnError) {
  EXPECT_THROW(orbis::eval::writeEvaluationPlot(dir_ / "plot.jpg", circlePlot()), orbis::Error);
  EXPECT_THROW(orbis::eval::writeEvaluationPlot(dir_ / "missing" / "plot.svg", circlePlot()), orbis::Error);
  EXPECT_THROW(orbis::eval::writeEvaluationPlot(dir_ / "missing" / "plot.png", circlePlot()), orbis::Error);
}

}  // namespace
