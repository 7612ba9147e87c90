// FeatureStorageReserve: what keep() returns equals what was built, in storage prepared
// beforehand (a batch at a time) for every frame after the first.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "features/feature_test_util.hpp"
#include "orbis/features/feature_storage.hpp"
#include "orbis/features/orb_extractor.hpp"

namespace orbis {
namespace {

FrameFeatures featuresOf(std::uint64_t seed, int budget) {
  OrbParams params;
  params.features = budget;
  OrbExtractor extractor(params);
  const cv::Mat image = test::texturedImage(640, 480, seed, 1500);
  FrameFeatures f = extractMonocular(extractor, image, PinholeCamera<double>{500.0, 500.0, 320.0, 240.0, 640, 480});
  f.depth[0] = 2.5f;  // a non-default value in every array
  f.uRight[0] = 100.f;
  return f;
}

void expectSame(const FrameFeatures& a, const FrameFeatures& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].u, b.keypoints[i].u);
    EXPECT_EQ(a.keypoints[i].octave, b.keypoints[i].octave);
    EXPECT_EQ(a.keypointsUn[i].v, b.keypointsUn[i].v);
    EXPECT_EQ(std::memcmp(&a.descriptors[i], &b.descriptors[i], sizeof(OrbDescriptor)), 0);
  }
  EXPECT_EQ(a.uRight, b.uRight);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.scales.scale, b.scales.scale);
  for (int cell = 0; cell < FeatureGrid::kCols * FeatureGrid::kRows; ++cell)
    EXPECT_EQ(a.grid.cellCount(cell), b.grid.cellCount(cell));
  const Keypoint& k = a.keypointsUn[a.size() / 2];
  std::vector<int> inA, inB;
  a.grid.forEachInArea(k.u, k.v, 30.f, -1, -1, [&](int index, int) { inA.push_back(index); });
  b.grid.forEachInArea(k.u, k.v, 30.f, -1, -1, [&](int index, int) { inB.push_back(index); });
  EXPECT_FALSE(inA.empty());
  EXPECT_EQ(inA, inB);
}

TEST(FeatureStorageReserve, KeepsEqualFeaturesInThePreparedStorage) {
  FeatureStorageReserve reserve;
  const FrameFeatures first = featuresOf(1, 1000), second = featuresOf(2, 1000);
  ASSERT_GT(first.size(), 500u);
  const FrameFeatures keptFirst = reserve.keep(first);  // nothing prepared yet: an ordinary copy
  expectSame(keptFirst, first);
  const FrameFeatures keptSecond = reserve.keep(second);
  expectSame(keptSecond, second);
  // The second went into the storage prepared for the first's size plus a margin.
  EXPECT_GT(keptSecond.keypoints.capacity(), first.size());
  EXPECT_GT(keptSecond.descriptors.capacity(), first.size());
  EXPECT_GT(keptSecond.keypointsUn.capacity(), first.size());
  EXPECT_GT(keptSecond.depth.capacity(), first.size());
}

TEST(FeatureStorageReserve, EveryFrameAfterTheFirstGoesIntoPreparedStorage) {
  FeatureStorageReserve reserve;
  const FrameFeatures f = featuresOf(5, 1000);
  const std::size_t preparedSize = f.size() + f.size() / 8 + 64;
  std::vector<FrameFeatures> kept;  // held, as keyframes hold theirs
  for (std::size_t i = 0; i < 3 * FeatureStorageReserve::kBatch + 1; ++i) kept.push_back(reserve.keep(f));
  for (std::size_t i = 0; i < kept.size(); ++i) {
    expectSame(kept[i], f);
    if (i == 0) continue;  // nothing prepared before the first
    // A plain copy would have a capacity of f.size().
    EXPECT_GE(kept[i].keypoints.capacity(), preparedSize) << "frame " << i;
    EXPECT_GE(kept[i].descriptors.capacity(), preparedSize) << "frame " << i;
  }
}

TEST(FeatureStorageReserve, AFrameLargerThanPreparedIsStillCopiedWhole) {
  FeatureStorageReserve reserve;
  reserve.keep(featuresOf(3, 300));
  const FrameFeatures large = featuresOf(4, 2000);
  ASSERT_GT(large.size(), 400u);
  expectSame(reserve.keep(large), large);
}

TEST(FeatureStorageReserve, PreparedStorageIsEmptyWithRoom) {
  const FrameFeatures f = FeatureStorageReserve::prepared(700);
  EXPECT_EQ(f.size(), 0u);
  EXPECT_GE(f.keypoints.capacity(), 700u);
  EXPECT_GE(f.descriptors.capacity(), 700u);
  EXPECT_GE(f.uRight.capacity(), 700u);
}

}  // namespace
}  // namespace orbis
