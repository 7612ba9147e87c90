// The standard room: closed, with every box placed inside it, clear of the camera path, and at
// a spread of distances; rectangles and texture coordinates map as the header says. The corridor
// preset: its loop runs clear of the central block, the boxes and the walls, and the block hides
// the start from half way round.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "orbis/synth/loop_trajectory.hpp"
#include "orbis/synth/scene.hpp"
#include "orbis/synth/sequence.hpp"

namespace orbis::synth {
namespace {

TEST(SynthScene, RoomHasAllBoxesInsideAndClearOfTheCameraPath) {
  const RoomParams room;
  const LoopTrajectoryParams path;
  for (std::uint64_t seed : {1u, 2u, 3u, 42u}) {
    const Scene scene = makeRoomScene(room, seed);
    ASSERT_EQ(scene.rects().size(), 6u + 5u * room.boxes) << "seed " << seed << ": every box placed";
    double nearestCentre = 1e9, farthestCentre = 0.0;
    for (std::size_t b = 0; b < static_cast<std::size_t>(room.boxes); ++b) {
      // Box b's five faces follow the six walls; the top face (axis 2, facing +1) is the last.
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = Eigen::Vector3d::Constant(-1e9);
      for (std::size_t f = 0; f < 5; ++f) {
        const SceneRect& r = scene.rects()[6 + 5 * b + f];
        for (const auto& [s, t] : {std::pair{0.0, 0.0}, std::pair{1e9, 1e9}}) {
          Eigen::Vector3d p;
          p[r.axis] = r.offset;
          p[(r.axis + 1) % 3] = s == 0.0 ? r.lo[0] : r.hi[0];
          p[(r.axis + 2) % 3] = t == 0.0 ? r.lo[1] : r.hi[1];
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
      }
      EXPECT_TRUE((lo.array() >= room.min.array()).all() && (hi.array() <= room.max.array()).all()) << "box " << b;
      EXPECT_DOUBLE_EQ(lo.z(), room.min.z()) << "boxes stand on the floor";
      // The camera path keeps at least half a metre from every box.
      for (int i = 0; i < 360; ++i) {
        const Eigen::Vector3d c = loopPose(path, i / 360.0).translation();
        const Eigen::Vector3d outside = (lo - c).cwiseMax(c - hi).cwiseMax(Eigen::Vector3d::Zero());
        ASSERT_GT(outside.norm(), 0.5) << "seed " << seed << " box " << b << " phase " << i / 360.0;
      }
      const double r = (0.5 * (lo + hi) - Eigen::Vector3d(0.0, 0.0, 0.5 * (lo.z() + hi.z()))).head<2>().norm();
      nearestCentre = std::min(nearestCentre, r);
      farthestCentre = std::max(farthestCentre, r);
    }
    EXPECT_GT(farthestCentre - nearestCentre, 0.8) << "seed " << seed << ": boxes at several depths";
  }
}

TEST(SynthScene, RaysFromInsideTheRoomAlwaysHitAndTexelsMapToPoints) {
  const Scene scene = makeRoomScene(RoomParams{}, 9);
  const Eigen::Vector3d origin(0.3, -0.2, 1.4);
  int hits = 0;
  for (int i = 0; i < 500; ++i) {
    const double az = 2.0 * M_PI * i / 500.0, el = std::asin(std::fmod(i * 0.618034, 1.0) * 1.8 - 0.9);
    const Eigen::Vector3d dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const auto hit = scene.intersect(origin, dir);
    ASSERT_TRUE(hit.has_value()) << "ray " << i << " escaped the closed room";
    // The hit point, rebuilt from the texel coordinates, is where the ray says it is.
    const Eigen::Vector3d p = scene.pointAt(hit->rect, hit->texel.x(), hit->texel.y());
    EXPECT_LT((p - (origin + hit->distance * dir)).norm(), 1e-9) << "ray " << i;
    ++hits;
  }
  EXPECT_EQ(hits, 500);
  // One-sided: from outside, the near wall (x = -5, 15 m away) is seen from behind and skipped;
  // the ray goes on to a box or the far wall's inner side.
  const auto fromOutside = scene.intersect(Eigen::Vector3d(-20.0, 0.0, 1.0), Eigen::Vector3d(1.0, 0.0, 0.0));
  ASSERT_TRUE(fromOutside.has_value());
  EXPECT_GT(fromOutside->distance, 15.0 + 1e-6);
}

TEST(SynthScene, CorridorLoopRunsClearOfBlockBoxesAndWallsAndTheBlockHidesTheStart) {
  RoomParams room;
  LoopTrajectoryParams path;
  applyScenePreset(ScenePreset::Corridor, room, path);
  for (std::uint64_t seed : {1u, 41u, 42u, 43u}) {
    const Scene scene = makeRoomScene(room, seed);
    // After the six walls every box, the central block last, has five faces.
    ASSERT_EQ((scene.rects().size() - 6) % 5, 0u);
    std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes;
    for (std::size_t first = 6; first < scene.rects().size(); first += 5) {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = Eigen::Vector3d::Constant(-1e9);
      for (std::size_t f = first; f < first + 5; ++f) {
        const SceneRect& r = scene.rects()[f];
        for (int corner = 0; corner < 2; ++corner) {
          Eigen::Vector3d p;
          p[r.axis] = r.offset;
          p[(r.axis + 1) % 3] = corner ? r.hi[0] : r.lo[0];
          p[(r.axis + 2) % 3] = corner ? r.hi[1] : r.lo[1];
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
      }
      boxes.emplace_back(lo, hi);
    }
    ASSERT_GE(boxes.size(), 2u) << "seed " << seed << ": the block and some boxes";
    EXPECT_NEAR(boxes.back().first.x(), -room.pillarHalf.x(), 1e-9) << "the block comes last";
    for (int i = 0; i < 360; ++i) {
      const Eigen::Vector3d c = loopPose(path, i / 360.0).translation();
      EXPECT_TRUE(((c - room.min).head<2>().array() > 1.0).all() && ((room.max - c).head<2>().array() > 1.0).all())
          << "a metre from the walls at phase " << i / 360.0;
      for (const auto& [lo, hi] : boxes) {
        const Eigen::Vector3d outside = (lo - c).cwiseMax(c - hi).cwiseMax(Eigen::Vector3d::Zero());
        ASSERT_GT(outside.norm(), 0.5) << "seed " << seed << " phase " << i / 360.0;
      }
    }
  }
  // Half way round, the block stands between the camera and where it started.
  const Scene scene = makeRoomScene(room, 1);
  const Eigen::Vector3d start = loopPose(path, 0.0).translation(), half = loopPose(path, 0.5).translation();
  const auto hit = scene.intersect(half, (start - half).normalized());
  ASSERT_TRUE(hit.has_value());
  EXPECT_LT(hit->distance, (start - half).norm() - 1.0);
}

}  // namespace
}  // namespace orbis::synth
