// A map point's observations (map/map_point.hpp, ObservationList) stay in keyframe-id order
// whatever order they arrive and leave in; distinctGoodPoints (map/key_frame.hpp) lists each good
// point once, in the order first met; KeyFrame::forEachPoint visits exactly the non-null slots,
// in slot order, whatever sequence of setPoint, erasePoint and setBad produced them.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "orbis/map/map.hpp"

namespace orbis {
namespace {

std::shared_ptr<const FrameFeatures> features(std::size_t n) {
  auto f = std::make_shared<FrameFeatures>();
  f->keypoints.resize(n);
  f->keypointsUn.resize(n);
  f->descriptors.resize(n);
  f->uRight.assign(n, -1.f);
  f->depth.assign(n, -1.f);
  return f;
}

std::vector<KeyFrame*> keyFrames(Map& map, int count, std::size_t keypoints) {
  std::vector<KeyFrame*> kfs;
  for (int k = 0; k < count; ++k)
    kfs.push_back(map.createKeyFrame(static_cast<std::uint64_t>(k), k, SE3d(), features(keypoints), MapIntrinsics{},
                                     bow::BowVector{}, bow::FeatureVector{}));
  return kfs;
}

std::vector<KeyFrameId> observerIds(const MapPoint& p) {
  std::vector<KeyFrameId> ids;
  for (const auto& [kf, index] : p.observations()) ids.push_back(kf->id);
  return ids;
}

TEST(MapPointObservations, StayInKeyFrameIdOrderWhateverTheOrderOfChanges) {
  Map map;
  const std::vector<KeyFrame*> kfs = keyFrames(map, 6, 4);
  MapPoint* p = map.createMapPoint(Eigen::Vector3d(0, 0, 1), kfs[0], 0);
  for (int k : {4, 1, 5, 0, 3, 2}) p->addObservation(kfs[static_cast<std::size_t>(k)], static_cast<std::size_t>(k % 4));
  p->addObservation(kfs[3], 2);  // already there: ignored
  EXPECT_EQ(observerIds(*p), (std::vector<KeyFrameId>{kfs[0]->id, kfs[1]->id, kfs[2]->id, kfs[3]->id, kfs[4]->id,
                                                      kfs[5]->id}));
  EXPECT_EQ(p->observationCount(), 6);
  EXPECT_EQ(p->indexIn(kfs[3]), 3);
  EXPECT_EQ(p->indexIn(kfs[5]), 1);
  EXPECT_FALSE(p->eraseObservation(kfs[2]));
  EXPECT_FALSE(p->eraseObservation(kfs[2]));  // gone already
  EXPECT_FALSE(p->isObservedBy(kfs[2]));
  EXPECT_EQ(p->indexIn(kfs[2]), -1);
  // The reference keyframe leaving hands the role to the observer with the lowest id.
  EXPECT_EQ(p->reference(), kfs[0]);
  EXPECT_FALSE(p->eraseObservation(kfs[0]));
  EXPECT_EQ(p->reference(), kfs[1]);
  EXPECT_EQ(observerIds(*p), (std::vector<KeyFrameId>{kfs[1]->id, kfs[3]->id, kfs[4]->id, kfs[5]->id}));
  // Two or fewer left: the point turns bad and lets go of every observation.
  EXPECT_FALSE(p->eraseObservation(kfs[4]));
  EXPECT_TRUE(p->eraseObservation(kfs[5]));
  EXPECT_TRUE(p->isBad());
  EXPECT_TRUE(p->observations().empty());
}

TEST(DistinctGoodPoints, ListsEachGoodPointOnceInTheOrderFirstMet) {
  Map map;
  const std::vector<KeyFrame*> kfs = keyFrames(map, 3, 4);
  std::vector<MapPoint*> points;
  for (int i = 0; i < 5; ++i) points.push_back(map.createMapPoint(Eigen::Vector3d(i, 0, 1), kfs[0], 0));
  // kf0: p3 p1 - p4 ; kf1: p1 p0 p3 (bad p2) ; kf2: p4 p0 - p1
  const std::vector<std::vector<int>> slots = {{3, 1, -1, 4}, {1, 0, 3, 2}, {4, 0, -1, 1}};
  for (std::size_t k = 0; k < slots.size(); ++k)
    for (std::size_t i = 0; i < slots[k].size(); ++i)
      if (slots[k][i] >= 0) kfs[k]->setPoint(i, points[static_cast<std::size_t>(slots[k][i])]);
  points[2]->setBad();
  EXPECT_EQ(distinctGoodPoints(kfs), (std::vector<MapPoint*>{points[3], points[1], points[4], points[0]}));
  EXPECT_EQ(distinctGoodPoints({kfs[2], kfs[1]}), (std::vector<MapPoint*>{points[4], points[0], points[1], points[3]}));
  EXPECT_TRUE(distinctGoodPoints({}).empty());
}

std::vector<MapPoint*> nonNullSlots(const KeyFrame& kf) {
  std::vector<MapPoint*> out;
  for (MapPoint* p : kf.points())
    if (p) out.push_back(p);
  return out;
}

std::vector<MapPoint*> visited(const KeyFrame& kf) {
  std::vector<MapPoint*> out;
  kf.forEachPoint([&](MapPoint* p) { out.push_back(p); });
  return out;
}

TEST(KeyFramePoints, ForEachPointVisitsTheNonNullSlotsInOrder) {
  std::mt19937 rng(7);
  // Slot counts below, at and across the 64-slot words of the occupancy bits.
  for (std::size_t slots : {1u, 63u, 64u, 65u, 200u, 1001u}) {
    Map map;
    KeyFrame* kf = map.createKeyFrame(0, 0, SE3d(), features(slots), MapIntrinsics{}, bow::BowVector{},
                                      bow::FeatureVector{});
    std::vector<MapPoint*> points;
    for (int k = 0; k < 8; ++k) points.push_back(map.createMapPoint(Eigen::Vector3d(0, 0, 1 + k), kf, 0));
    EXPECT_TRUE(visited(*kf).empty());
    std::uniform_int_distribution<std::size_t> slot(0, slots - 1), which(0, points.size());
    for (int step = 0; step < 3000; ++step) {
      const std::size_t i = slot(rng), w = which(rng);
      switch (step % 4) {
        case 0:
        case 1: kf->setPoint(i, w < points.size() ? points[w] : nullptr); break;  // null included
        case 2: kf->erasePoint(i); break;
        default: if (w < points.size()) kf->erasePoint(points[w]);  // every slot holding it
      }
      ASSERT_EQ(visited(*kf), nonNullSlots(*kf)) << slots << " slots, step " << step;
    }
    kf->setPoint(slots - 1, points[0]);
    kf->setPoint(0, points[1]);
    EXPECT_EQ(visited(*kf), nonNullSlots(*kf));
    EXPECT_EQ(visited(*kf).back(), slots == 1 ? points[1] : points[0]);  // one slot: overwritten
    EXPECT_EQ(visited(*kf).front(), points[1]);
  }
}

TEST(KeyFramePoints, BadKeyFrameVisitsNothing) {
  Map map;
  KeyFrame* root = map.createKeyFrame(0, 0, SE3d(), features(100), MapIntrinsics{}, bow::BowVector{},
                                      bow::FeatureVector{});
  KeyFrame* kf = map.createKeyFrame(1, 1, SE3d(), features(100), MapIntrinsics{}, bow::BowVector{},
                                    bow::FeatureVector{});
  MapPoint* p = map.createMapPoint(Eigen::Vector3d(0, 0, 1), root, 0);
  for (std::size_t i : {3u, 64u, 99u}) kf->setPoint(i, p);
  EXPECT_EQ(visited(*kf).size(), 3u);
  ASSERT_TRUE(kf->setBad());
  EXPECT_TRUE(visited(*kf).empty());
  EXPECT_TRUE(nonNullSlots(*kf).empty());
}

}  // namespace
}  // namespace orbis
