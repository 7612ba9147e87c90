// The keyframe-to-keyframe searches of loop closing (map/keyframe_matching.hpp) on two views of a
// textured plane with known motion (features/plane_views.hpp), each view's points in a map of its
// own: for a monocular loop the second map has drifted to another scale, and only the similarity
// between the two cameras finds its points in the first image.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <unordered_map>

#include "features/plane_views.hpp"
#include "orbis/map/keyframe_matching.hpp"

namespace orbis {
namespace {

using test::PlaneViews;
using test::planeViews;

MapIntrinsics imageBounds(const PinholeCamera<double>& camera) {
  MapIntrinsics bounds;
  bounds.fx = camera.fx;
  bounds.fy = camera.fy;
  bounds.cx = camera.cx;
  bounds.cy = camera.cy;
  bounds.maxX = camera.width;
  bounds.maxY = camera.height;
  return bounds;
}

// One map point per keypoint of `kf`, at `cameraPoint(i)` in its camera, with its descriptor.
template <class CameraPoint>
void addPoints(Map& map, KeyFrame* kf, CameraPoint cameraPoint, std::unordered_map<const MapPoint*, std::size_t>& keypointOf) {
  const SE3d Twc = kf->Twc();
  for (std::size_t i = 0; i < kf->size(); ++i) {
    MapPoint* p = map.createMapPoint(Twc * cameraPoint(i), kf, 0);
    p->setDescriptor(kf->features().descriptors[i]);
    p->addObservation(kf, i);
    kf->setPoint(i, p);
    p->updateNormalAndDepth();
    keypointOf[p] = i;
  }
}

// Camera 2 has drifted: its map is 2.5 times the scale of camera 1's, and its world is another
// frame altogether (another pose of the same keyframe). S12 takes its camera coordinates home.
TEST(KeyFrameMatching, BySim3FindsTheOtherMapsPointsAcrossAScaleDrift) {
  const PlaneViews s = planeViews(4.0, {0.2, -0.05, 0.1}, 41);
  const double drift = 2.5;
  const MapIntrinsics bounds = imageBounds(s.camera);
  const auto f1 = std::make_shared<const FrameFeatures>(s.f1);
  const auto f2 = std::make_shared<const FrameFeatures>(s.f2);
  Map map;
  bow::FeatureVector none;
  KeyFrame* kf1 = map.createKeyFrame(0, 0.0, SE3d(), f1, bounds, {}, none);
  Eigen::Matrix<double, 6, 1> xi;
  xi << 1.0, -2.0, 0.5, 0.3, 0.2, -0.4;
  KeyFrame* kf2 = map.createKeyFrame(1, 1.0, SE3d::exp(xi), f2, bounds, {}, none);
  std::unordered_map<const MapPoint*, std::size_t> keypointOf;
  addPoints(map, kf1, [&](std::size_t i) { return s.pointOf(f1->keypointsUn[i]); }, keypointOf);
  // View 2's keypoints back onto the plane (through the homography to view 1), then into camera
  // 2 at the drifted scale.
  const Eigen::Matrix3d H12 = s.H21.inverse();
  addPoints(map, kf2, [&](std::size_t j) {
    const Keypoint& k = f2->keypointsUn[j];
    const Eigen::Vector3d h = H12 * Eigen::Vector3d(k.u, k.v, 1.0);
    Keypoint in1 = k;
    in1.u = static_cast<float>(h.x() / h.z());
    in1.v = static_cast<float>(h.y() / h.z());
    return Eigen::Vector3d(drift * (s.R21 * s.pointOf(in1) + s.t21));
  }, keypointOf);

  // X1 = R21ᵀ·(X2 / drift − t21).
  const Sim3d S12(1.0 / drift, Eigen::Matrix3d(s.R21.transpose()), Eigen::Vector3d(-s.R21.transpose() * s.t21));
  const auto search = [&](const Sim3d& S) {
    std::vector<MapPoint*> matches(kf1->size(), nullptr);
    const int n = matching::matchBySim3(s.camera, *kf1, *kf2, S, matches);
    test::Tally t;
    for (std::size_t i = 0; i < matches.size(); ++i) {
      if (!matches[i]) continue;
      const std::size_t j = keypointOf.at(matches[i]);
      ++t.matched;
      t.correct += s.correct(static_cast<int>(i), static_cast<int>(j), 3.0 * f2->scales.scale[static_cast<std::size_t>(f2->keypointsUn[j].octave)]);
    }
    EXPECT_EQ(n, t.matched);
    return t;
  };
  const test::Tally right = search(S12);
  // The rigid motion between the cameras, blind to the drift: the points land elsewhere.
  const test::Tally unscaled = search(Sim3d(1.0, S12.so3(), S12.translation()));
  std::printf("[ matching ] by Sim(3) across a %.1fx scale drift: %d matched / %d correct; ignoring the drift %d / %d\n",
              drift, right.matched, right.correct, unscaled.matched, unscaled.correct);
  EXPECT_GT(right.correct, static_cast<int>(f1->size()) / 4);
  EXPECT_GE(right.correct, right.matched * 9 / 10);
  EXPECT_LT(unscaled.correct, right.correct / 3);
  // Matches already in the slots are kept and not searched again.
  std::vector<MapPoint*> seeded(kf1->size(), nullptr);
  seeded[0] = kf2->point(0);
  const int added = matching::matchBySim3(s.camera, *kf1, *kf2, S12, seeded);
  EXPECT_EQ(seeded[0], kf2->point(0));
  EXPECT_LE(added, right.matched);
}

}  // namespace
}  // namespace orbis
