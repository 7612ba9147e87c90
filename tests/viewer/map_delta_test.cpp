// MapDeltaEncoder (src/viewer/map_delta.hpp): the first message holds the whole map, the next only
// what changed (new, moved beyond the tolerance, removed; a changed local-map flag), and full()
// the whole scene as the pages were sent it. Read back from the JSON as the page reads it.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>
#include <vector>

#include "map_delta.hpp"

namespace orbis::viewer_detail {
namespace {

// The numbers of the flat array `"name":[...]` in `json`.
std::vector<double> numbersOf(const std::string& json, const std::string& name) {
  const std::string open = "\"" + name + "\":[";
  const std::size_t begin = json.find(open);
  EXPECT_NE(begin, std::string::npos) << name;
  if (begin == std::string::npos) return {};
  const std::size_t first = begin + open.size();
  const std::string list = json.substr(first, json.find(']', first) - first);
  std::vector<double> numbers;
  std::size_t at = 0;
  while (at < list.size()) {
    std::size_t end = list.find(',', at);
    if (end == std::string::npos) end = list.size();
    numbers.push_back(std::stod(list.substr(at, end - at)));
    at = end + 1;
  }
  return numbers;
}

std::set<long long> pointIds(const std::string& json) {  // points: id, x, y, z, firstKeyFrame, local
  const std::vector<double> p = numbersOf(json, "points");
  EXPECT_EQ(p.size() % 6, 0u);
  std::set<long long> ids;
  for (std::size_t i = 0; i + 5 < p.size(); i += 6) ids.insert(static_cast<long long>(p[i]));
  return ids;
}

std::set<long long> keyFrameIds(const std::string& json) {
  const std::size_t begin = json.find("\"keyFrames\":["), end = json.find("\"removedKeyFrames\"");
  std::set<long long> ids;
  const std::string section = json.substr(begin, end - begin);
  const std::regex id("\\{\"id\":(\\d+)");
  for (auto it = std::sregex_iterator(section.begin(), section.end(), id); it != std::sregex_iterator(); ++it)
    ids.insert(std::stoll((*it)[1]));
  return ids;
}

std::set<long long> idsOf(const std::string& json, const std::string& name) {
  std::set<long long> ids;
  for (double v : numbersOf(json, name)) ids.insert(static_cast<long long>(v));
  return ids;
}

KeyFrameSnapshot keyFrameAt(KeyFrameId id, double x) {
  KeyFrameSnapshot k;
  k.id = id;
  k.Twc = SE3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(x, 0, 0));
  return k;
}

MapSnapshot firstMap() {
  MapSnapshot map;
  map.keyFrames = {keyFrameAt(0, 0), keyFrameAt(1, 0.5)};
  map.points = {{1, {0, 0, 1}, 0}, {2, {1, 0, 1}, 0}, {3, {0, 1, 1}, 1}};
  map.trajectory = {{0, 0, 0}, {0.5f, 0, 0}};
  map.frames = 2;
  return map;
}

// Point 1 gone, 2 moved by less than the tolerance, 3 by more, 4 new; keyframe 1 and the second
// camera moved; a third camera.
MapSnapshot secondMap() {
  MapSnapshot map = firstMap();
  map.keyFrames[1] = keyFrameAt(1, 0.52);
  map.points = {{2, {1.0004f, 0, 1}, 0}, {3, {0, 1.01f, 1}, 1}, {4, {2, 2, 2}, 1}};
  map.trajectory = {{0, 0, 0}, {0.52f, 0, 0}, {1, 0, 0}};
  map.frames = 3;
  return map;
}

TEST(MapDeltaEncoder, FirstMessageHoldsTheWholeMap) {
  MapDeltaEncoder encoder;
  const MapDeltaEncoder::Message first = encoder.encode(firstMap(), {}, true);
  EXPECT_EQ(first.seq, 1u);
  EXPECT_EQ(pointIds(first.json), (std::set<long long>{1, 2, 3}));
  EXPECT_EQ(keyFrameIds(first.json), (std::set<long long>{0, 1}));
  EXPECT_EQ(numbersOf(first.json, "trajectory").size(), 6u);
  EXPECT_NE(first.json.find("\"trajectoryFrom\":0"), std::string::npos);
}

TEST(MapDeltaEncoder, NextMessageHoldsOnlyWhatChanged) {
  MapDeltaEncoder encoder;
  encoder.encode(firstMap(), {}, true);
  const MapDeltaEncoder::Message second = encoder.encode(secondMap(), {}, false);
  EXPECT_EQ(second.seq, 2u);
  EXPECT_NE(second.json.find("\"full\":false"), std::string::npos);
  EXPECT_NE(second.json.find("\"live\":false"), std::string::npos);
  EXPECT_EQ(pointIds(second.json), (std::set<long long>{3, 4}));  // 2 moved by 0.4 mm only
  EXPECT_EQ(idsOf(second.json, "removedPoints"), (std::set<long long>{1}));
  EXPECT_EQ(keyFrameIds(second.json), (std::set<long long>{1}));
  EXPECT_TRUE(idsOf(second.json, "removedKeyFrames").empty());
  EXPECT_NE(second.json.find("\"trajectoryFrom\":1"), std::string::npos);  // the second camera moved
  EXPECT_EQ(numbersOf(second.json, "trajectory").size(), 6u);
  EXPECT_NE(second.json.find("\"trajectoryLength\":3"), std::string::npos);
}

TEST(MapDeltaEncoder, ALocalMapFlagThatChangesIsSent) {
  MapDeltaEncoder encoder;
  encoder.encode(firstMap(), {}, true);
  const MapDeltaEncoder::Message second = encoder.encode(firstMap(), {2}, true);
  EXPECT_EQ(pointIds(second.json), (std::set<long long>{2}));
  const std::vector<double> p = numbersOf(second.json, "points");
  ASSERT_EQ(p.size(), 6u);
  EXPECT_EQ(p[5], 1.0);
  EXPECT_TRUE(keyFrameIds(second.json).empty());
  EXPECT_EQ(numbersOf(encoder.encode(firstMap(), {2}, true).json, "points").size(), 0u);  // nothing new
}

TEST(MapDeltaEncoder, FullHoldsTheSceneAsSent) {
  MapDeltaEncoder encoder;
  encoder.encode(firstMap(), {}, true);
  encoder.encode(secondMap(), {}, true);
  const MapDeltaEncoder::Message whole = encoder.full();
  EXPECT_EQ(whole.seq, 2u);
  EXPECT_NE(whole.json.find("\"full\":true"), std::string::npos);
  EXPECT_EQ(pointIds(whole.json), (std::set<long long>{2, 3, 4}));
  EXPECT_EQ(keyFrameIds(whole.json), (std::set<long long>{0, 1}));
  EXPECT_EQ(numbersOf(whole.json, "trajectory").size(), 9u);
  // Point 2 as it was sent (x 1.0), not as it moved within the tolerance (x 1.0004).
  const std::vector<double> p = numbersOf(whole.json, "points");
  for (std::size_t i = 0; i < p.size(); i += 6)
    if (p[i] == 2) EXPECT_EQ(p[i + 1], 1.0);
}

}  // namespace
}  // namespace orbis::viewer_detail
