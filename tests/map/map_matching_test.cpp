// The map-level searches (map/map_matching.hpp) on keyframes, frames and map points built over
// two views of a textured plane with known camera motion (features/plane_views.hpp): every
// keypoint of view 1 has a known 3-D point and a known position in view 2, so each search is
// checked for finding right matches and for following the geometry it is given.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "features/plane_views.hpp"
#include "orbis/camera/stereo.hpp"
#include "orbis/features/matcher.hpp"
#include "orbis/map/map.hpp"
#include "orbis/map/map_matching.hpp"

namespace orbis {
namespace {

using test::PlaneViews;
using test::planeViews;
using test::Tally;

MapIntrinsics imageBounds(const PinholeCamera<double>& camera, double bf) {
  MapIntrinsics bounds;
  bounds.fx = camera.fx;
  bounds.fy = camera.fy;
  bounds.cx = camera.cx;
  bounds.cy = camera.cy;
  bounds.bf = bf;
  bounds.maxX = camera.width;
  bounds.maxY = camera.height;
  return bounds;
}

// Every keypoint in one vocabulary node: each keypoint's candidates are all the keypoints of the
// other keyframe in that node.
bow::FeatureVector allInNode(std::size_t keypoints, bow::NodeId node) {
  std::vector<std::pair<bow::NodeId, std::uint32_t>> pairs;
  for (std::uint32_t i = 0; i < keypoints; ++i) pairs.emplace_back(node, i);
  return bow::FeatureVector::fromPairs(std::move(pairs));
}

// Forward motion towards the plane magnifies it by 3 / 2.4 = 1.25: points reappear one octave
// up. A stereo camera that advanced more than its baseline searches only octaves >= the last
// one, which keeps them; when the poses say it retreated, only octaves <= the last one are
// searched, which finds fewer of them.
TEST(MapMatching, FromLastFrameSearchesStereoOctavesByMotion) {
  const PlaneViews s = planeViews(0.0, {0.0, 0.0, -0.6}, 32);
  using Camera = RectifiedStereoCamera<double>;
  const Camera camera(s.camera, 0.1);  // baseline 0.1 m, well below the 0.6 m advance
  const MapIntrinsics bounds = imageBounds(s.camera, camera.bf());
  const auto f1 = std::make_shared<const FrameFeatures>(s.f1);
  const auto f2 = std::make_shared<const FrameFeatures>(s.f2);

  Map map;
  KeyFrame* kf = map.createKeyFrame(0, 0.0, SE3d(), f1, bounds, {}, allInNode(f1->size(), 0));
  Frame<Camera> last;
  last.features = f1;
  last.camera = &camera;
  last.intrinsics = bounds;
  last.resetMatches();
  std::unordered_map<const MapPoint*, std::size_t> keypointOf;  // in view 1
  for (std::size_t i = 0; i < f1->size(); ++i) {
    MapPoint* p = map.createMapPoint(s.pointOf(f1->keypointsUn[i]), kf, 0);
    p->setDescriptor(f1->descriptors[i]);
    p->addObservation(kf, i);
    kf->setPoint(i, p);
    last.points[i] = p;
    keypointOf[p] = i;
  }
  Frame<Camera> current;
  current.features = f2;
  current.camera = &camera;
  current.intrinsics = bounds;
  current.Tcw = SE3d(s.R21, s.t21);

  const auto search = [&](bool forward) {
    current.resetMatches();
    const int n = matching::matchFromLastFrame(current, last, 7.f, true);
    Tally t;
    for (std::size_t j = 0; j < current.size(); ++j) {
      if (!current.points[j]) continue;
      const std::size_t i = keypointOf.at(current.points[j]);
      const int octave = f2->keypointsUn[j].octave, lastOctave = f1->keypointsUn[i].octave;
      ++t.matched;
      t.correct += s.correct(static_cast<int>(i), static_cast<int>(j), 3.0 * f2->scales.scale[static_cast<std::size_t>(octave)]);
      if (forward) EXPECT_GE(octave, lastOctave);
      else EXPECT_LE(octave, lastOctave);
    }
    EXPECT_EQ(n, t.matched);
    return t;
  };
  const Tally forward = search(true);
  // The last pose 1.2 m further along the axis: the camera now reads as retreating by 0.6 m.
  last.Tcw = SE3d(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, 0.0, -1.2));
  const Tally backward = search(false);
  std::printf("[ matching ] from last frame, forward motion: forward window %d matched / %d correct, "
              "backward window %d / %d\n", forward.matched, forward.correct, backward.matched, backward.correct);
  EXPECT_GT(forward.correct, static_cast<int>(f1->size()) / 4);
  EXPECT_GE(forward.correct, forward.matched * 9 / 10);
  EXPECT_GT(forward.correct, backward.correct);

  // A foreign descriptor on every point (a fixed shift): far fewer matches survive kThHigh and
  // the rotation check (unrelated ORB descriptors are correlated enough that some pass, as in
  // ORB-SLAM).
  for (std::size_t i = 0; i < f1->size(); ++i)
    last.points[i]->setDescriptor(f1->descriptors[(i + f1->size() / 2) % f1->size()]);
  last.Tcw = SE3d();
  const Tally foreign = search(true);
  std::printf("[ matching ] from last frame with foreign descriptors: %d matched\n", foreign.matched);
  EXPECT_LT(foreign.matched, forward.correct / 2);
}

// Epipolar search between two keyframes: with the true relative pose most pairs are right;
// with a wrong one (translation along y instead of x) the lines lie elsewhere and few are.
TEST(MapMatching, ForTriangulationFollowsTheEpipolarGeometry) {
  const PlaneViews s = planeViews(3.0, {0.25, 0.05, 0.02}, 34);
  const Eigen::Matrix3d K = s.camera.K();
  const MapIntrinsics bounds = imageBounds(s.camera, 0.0);
  const auto f1 = std::make_shared<const FrameFeatures>(s.f1);
  const auto f2 = std::make_shared<const FrameFeatures>(s.f2);
  Map map;
  KeyFrame* kf1 = map.createKeyFrame(0, 0.0, SE3d(), f1, bounds, {}, allInNode(f1->size(), 1));
  KeyFrame* kf2 = map.createKeyFrame(1, 1.0, SE3d(s.R21, s.t21), f2, bounds, {}, allInNode(f2->size(), 1));
  // F maps kf1's pixels to lines in kf2 (x2ᵀ F x1 = 0).
  const auto pairs = matching::matchForTriangulation(s.camera, *kf1, *kf2, fundamentalFromPose(s.R21, s.t21, K, K), false);
  int correct = 0;
  std::set<int> bins;  // of the orientation change, as RotationHistogram files them
  for (const auto& [i1, i2] : pairs) {
    const Keypoint& k2 = f2->keypointsUn[i2];
    correct += s.correct(static_cast<int>(i1), static_cast<int>(i2), 3.0 * f2->scales.scale[static_cast<std::size_t>(k2.octave)]);
    float a = std::fmod(f1->keypointsUn[i1].angle - k2.angle, 360.f);
    if (a < 0.f) a += 360.f;
    bins.insert(static_cast<int>(std::lround(a * RotationHistogram::kBins / 360.f)) % RotationHistogram::kBins);
  }
  const Eigen::Vector3d wrongT(0.02, 0.25, 0.05);
  KeyFrame* kf2Wrong = map.createKeyFrame(2, 2.0, SE3d(s.R21, wrongT), f2, bounds, {}, allInNode(f2->size(), 1));
  const auto wrongPairs = matching::matchForTriangulation(s.camera, *kf1, *kf2Wrong, fundamentalFromPose(s.R21, wrongT, K, K), false);
  int wrongCorrect = 0;
  for (const auto& [i1, i2] : wrongPairs) wrongCorrect += s.correct(static_cast<int>(i1), static_cast<int>(i2), 3.0);
  std::printf("[ matching ] epipolar: %zu pairs, %d correct; with a wrong pose %zu pairs, %d correct\n", pairs.size(),
              correct, wrongPairs.size(), wrongCorrect);
  EXPECT_GT(pairs.size(), f1->size() / 4);
  EXPECT_GE(correct, static_cast<int>(pairs.size()) * 9 / 10);
  EXPECT_LT(wrongCorrect, correct / 3);
  // The rotation check keeps at most the three dominant orientation changes.
  EXPECT_LE(bins.size(), 3u);
  // Candidates come from the shared vocabulary node only: kf2's keypoints in another node match nothing.
  KeyFrame* kf2Elsewhere = map.createKeyFrame(3, 3.0, SE3d(s.R21, s.t21), f2, bounds, {}, allInNode(f2->size(), 2));
  EXPECT_TRUE(matching::matchForTriangulation(s.camera, *kf1, *kf2Elsewhere, fundamentalFromPose(s.R21, s.t21, K, K), false)
                  .empty());
}

}  // namespace
}  // namespace orbis
