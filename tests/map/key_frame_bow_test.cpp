// A keyframe's bag of words left for later (map/key_frame.hpp, BowComputation): computed once, by
// whichever thread asks first, and the same words for every reader.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "orbis/map/map.hpp"

namespace orbis {
namespace {

TEST(KeyFrameBow, LeftForLaterIsComputedOnceByTheFirstReader) {
  Map map;
  std::atomic<int> calls{0};
  KeyFrame* kf = map.createKeyFrame(
      0, 0.0, SE3d(), std::make_shared<const FrameFeatures>(), MapIntrinsics{},
      [&](const FrameFeatures&, bow::BowVector& words, bow::FeatureVector& nodes) {
        ++calls;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // readers arrive meanwhile
        words = bow::BowVector::fromUnsorted({{9, 0.75}, {3, 0.25}}, false);
        nodes = bow::FeatureVector::fromPairs({{4, 0u}});
      });
  EXPECT_EQ(calls.load(), 0);
  std::vector<std::thread> readers;
  std::atomic<int> sawBoth{0};
  for (int t = 0; t < 4; ++t)
    readers.emplace_back([&] {
      if (kf->bowVector().size() == 2 && kf->featureVector().size() == 1) ++sawBoth;
    });
  for (std::thread& t : readers) t.join();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_EQ(sawBoth.load(), 4) << "every reader waits for the one computation";
  EXPECT_EQ(kf->bowVector()[1].word, 9u);
}

TEST(KeyFrameBow, GivenVectorsAreKept) {
  Map map;
  KeyFrame* kf = map.createKeyFrame(0, 0.0, SE3d(), std::make_shared<const FrameFeatures>(), MapIntrinsics{},
                                    bow::BowVector::fromUnsorted({{5, 1.0}}, false), bow::FeatureVector{});
  kf->ensureBow();
  ASSERT_EQ(kf->bowVector().size(), 1u);
  EXPECT_EQ(kf->bowVector()[0].word, 5u);
}

}  // namespace
}  // namespace orbis
