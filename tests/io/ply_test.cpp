#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <cstring>

#include "orbis/io/ply.hpp"
#include "orbis/util/error.hpp"

TEST(Ply, WritesHeaderAndBinaryVertices) {
  const auto path = std::filesystem::temp_directory_path() / "orbis_ply_test.ply";
  std::vector<Eigen::Vector3f> pts{{1, 2, 3}, {4, 5, 6}};
  orbis::writePly(path, pts, {{{255, 0, 0}}, {{0, 255, 0}}});
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  const auto end = s.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_NE(s.find("element vertex 2"), std::string::npos);
  EXPECT_EQ(s.size() - (end + 11), 2u * (12 + 3));
  float x;
  std::memcpy(&x, s.data() + end + 11 + 12 + 3, 4);
  EXPECT_FLOAT_EQ(x, 4.0f);
  std::filesystem::remove(path);
}

TEST(Ply, UnwritablePathNamesTheFile) {
  try {
    orbis::writePly("/nonexistent-dir/x.ply", {});
    FAIL();
  } catch (const orbis::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.ply"), std::string::npos);
  }
}

TEST(Ply, ReadsBackWhatItWrote) {
  const auto path = std::filesystem::temp_directory_path() / "orbis_ply_read_test.ply";
  const std::vector<Eigen::Vector3f> points{{1, 2, 3}, {-4, 5.5f, 6}};
  orbis::writePly(path, points, {{{255, 0, 0}}, {{0, 255, 0}}});
  const std::vector<Eigen::Vector3f> read = orbis::readPly(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[1], points[1]);
  orbis::writePly(path, points);
  EXPECT_EQ(orbis::readPly(path)[0], points[0]);
  std::filesystem::remove(path);
  EXPECT_THROW(orbis::readPly(path), orbis::Error);
}
