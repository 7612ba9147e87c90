// tests/features/plane_views.hpp — two views of a textured plane with known camera motion:
// every keypoint of view 1 has a known 3-D point and a known position in view 2 (the
// plane-induced homography), so a search can be checked for finding right matches and for
// rejecting wrong ones. Used by the feature-level and the map-level matching tests.
#pragma once

#include <cmath>
#include <cstdint>

#include <Eigen/Geometry>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "features/feature_test_util.hpp"
#include "orbis/features/frame_features.hpp"
#include "orbis/features/orb_extractor.hpp"

namespace orbis::test {

constexpr double kPlaneDepth = 3.0;  // plane z = 3 m in camera 1

struct PlaneViews {
  PinholeCamera<double> camera{500.0, 500.0, 320.0, 240.0, 640, 480};
  Eigen::Matrix3d R21;
  Eigen::Vector3d t21;
  Eigen::Matrix3d H21;  // pixel of view 1 -> pixel of view 2
  FrameFeatures f1, f2;

  Eigen::Vector3d pointOf(const Keypoint& k) const {  // on the plane, camera-1 frame
    return camera.unproject(Eigen::Vector2d(k.u, k.v), kPlaneDepth);
  }
  Eigen::Vector2d inView2(const Keypoint& k) const { return camera.project(R21 * pointOf(k) + t21); }
  bool correct(int i1, int i2, double tolerance) const {
    const Eigen::Vector2d p = inView2(f1.keypointsUn[static_cast<std::size_t>(i1)]);
    const Keypoint& k2 = f2.keypointsUn[static_cast<std::size_t>(i2)];
    return (p - Eigen::Vector2d(k2.u, k2.v)).norm() < tolerance;
  }
};

inline PlaneViews planeViews(double yawDeg, const Eigen::Vector3d& t21, std::uint64_t seed) {
  PlaneViews s;
  s.R21 = Eigen::AngleAxisd(yawDeg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.t21 = t21;
  const Eigen::Matrix3d K = s.camera.K();
  const Eigen::Vector3d n(0, 0, 1);
  s.H21 = K * (s.R21 + t21 * n.transpose() / kPlaneDepth) * K.inverse();
  const cv::Mat img1 = test::texturedImage(640, 480, seed, 1500);
  cv::Mat H;
  cv::eigen2cv(s.H21, H);
  cv::Mat img2;
  cv::warpPerspective(img1, img2, H, img1.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  OrbExtractor ex;
  s.f1 = extractMonocular(ex, img1, s.camera);
  s.f2 = extractMonocular(ex, img2, s.camera);
  return s;
}

// Matches a search returned, and how many of them the known geometry confirms.
struct Tally {
  int matched = 0, correct = 0;
};

}  // namespace orbis::test
