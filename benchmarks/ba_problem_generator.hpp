// benchmarks/ba_problem_generator.hpp — seeded, SLAM-shaped bundle-adjustment problems with exact
// ground truth: a stereo rig moving sideways past a field of points, observations at ORB pyramid
// levels (σ = 1.2^octave px, information 1/σ²), a mix of stereo and monocular measurements, a
// fraction of gross outliers, perturbed starting poses and points.
//
// Contract: makeSlamScene(spec) is a pure function of spec (including spec.seed). The first
// spec.fixedKeyframes poses are exact and meant to be held fixed; motion-only scenes have one
// pose and exact (fixed) points. Used by the Ceres comparison benchmark and by the optim tests.
#pragma once

#include "orbis/camera/stereo.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/optim/slam_ba.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace orbis::bench {

struct SlamSceneSpec {
  int keyframes = 15;
  int points = 3000;
  int minObservationsPerPoint = 3;
  int maxObservationsPerPoint = 12;
  double stereoFraction = 0.5;
  double outlierFraction = 0.05;
  double pixelNoise = 1.0;        // σ at octave 0
  double keyframeSpacing = 0.25;  // metres between consecutive keyframes
  double poseNoiseRotation = 0.01;      // rad, on free poses
  double poseNoiseTranslation = 0.05;   // m
  double pointNoise = 0.05;             // m
  int fixedKeyframes = 3;
  unsigned seed = 1;
};

struct SlamScene {
  RectifiedStereoCamera<double> camera;
  std::vector<SE3d> truePoses, initialPoses;  // camera-from-world
  std::vector<char> poseFixed;
  std::vector<Eigen::Vector3d> truePoints, initialPoints;
  std::vector<optim::SlamObservation> observations;
  std::vector<char> isOutlier;
};

inline SE3d perturb(const SE3d& pose, std::mt19937& rng, double rotation, double translation) {
  std::normal_distribution<double> n(0.0, 1.0);
  SE3d::Tangent xi;
  for (int k = 0; k < 3; ++k) xi[k] = translation * n(rng);
  for (int k = 3; k < 6; ++k) xi[k] = rotation * n(rng);
  return SE3d::exp(xi) * pose;
}

// KITTI-like rectified stereo: 1226×370, f = 718.9, baseline 0.54 m (bf ≈ 386).
inline RectifiedStereoCamera<double> benchmarkCamera() {
  return RectifiedStereoCamera<double>({718.856, 718.856, 607.193, 185.216, 1226, 370}, 0.537);
}

inline SlamScene makeSlamScene(const SlamSceneSpec& spec) {
  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  SlamScene scene;
  scene.camera = benchmarkCamera();
  const auto& pin = scene.camera.pinhole;

  // Keyframes move along x with a gentle weave in y and yaw, all looking down +z.
  for (int k = 0; k < spec.keyframes; ++k) {
    const double x = spec.keyframeSpacing * k;
    SE3d::Tangent xi = SE3d::Tangent::Zero();
    xi[4] = 0.05 * std::sin(0.1 * k);
    const SE3d worldFromCamera(SO3d::exp(xi.tail<3>()), Eigen::Vector3d(x, 0.1 * std::sin(0.3 * k), 0.0));
    scene.truePoses.push_back(worldFromCamera.inverse());
    const bool fixed = k < spec.fixedKeyframes;
    scene.poseFixed.push_back(fixed);
    scene.initialPoses.push_back(
        fixed ? scene.truePoses.back()
              : perturb(scene.truePoses.back(), rng, spec.poseNoiseRotation, spec.poseNoiseTranslation));
  }

  std::vector<int> visible;
  while (static_cast<int>(scene.truePoints.size()) < spec.points) {
    // A point seen from an anchor keyframe, at 3–25 m, anywhere in its image.
    const int anchor = static_cast<int>(uni(rng) * spec.keyframes) % spec.keyframes;
    const double depth = 3.0 + 22.0 * uni(rng) * uni(rng);
    const Eigen::Vector2d pixel(uni(rng) * pin.width, uni(rng) * pin.height);
    const Eigen::Vector3d world = scene.truePoses[anchor].inverse() * pin.unproject(pixel, depth);
    visible.clear();
    for (int k = 0; k < spec.keyframes; ++k) {
      const Eigen::Vector3d pc = scene.truePoses[k] * world;
      if (pc.z() < 0.5) continue;
      const Eigen::Vector2d px = pin.project(pc);
      if (pin.inImage(px.x(), px.y())) visible.push_back(k);
    }
    const int want = spec.minObservationsPerPoint +
                     static_cast<int>(uni(rng) * (spec.maxObservationsPerPoint - spec.minObservationsPerPoint + 1));
    if (static_cast<int>(visible.size()) < std::min(want, spec.minObservationsPerPoint)) continue;
    // Keep the keyframes nearest the anchor, as covisibility would.
    std::stable_sort(visible.begin(), visible.end(),
                     [&](int a, int b) { return std::abs(a - anchor) < std::abs(b - anchor); });
    visible.resize(std::min<std::size_t>(visible.size(), want));
    std::sort(visible.begin(), visible.end());

    const int point = static_cast<int>(scene.truePoints.size());
    scene.truePoints.push_back(world);
    scene.initialPoints.push_back(world + spec.pointNoise * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
    for (int k : visible) {
      const Eigen::Vector3d pc = scene.truePoses[k] * world;
      const int octave = static_cast<int>(uni(rng) * 8) % 8;
      const double sigma = spec.pixelNoise * std::pow(1.2, octave);
      Eigen::Vector3d z = scene.camera.project(pc);
      z += sigma * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
      const bool stereo = uni(rng) < spec.stereoFraction && pc.z() < scene.camera.closeDepthThreshold();
      const bool outlier = uni(rng) < spec.outlierFraction;
      if (outlier) {
        const double angle = 2.0 * M_PI * uni(rng), radius = 20.0 + 40.0 * uni(rng);
        z.x() += radius * std::cos(angle);
        z.y() += radius * std::sin(angle);
        z.z() = z.x() - (scene.camera.bf() / pc.z()) + 10.0 * gauss(rng);
      }
      if (!stereo) z.z() = -1.0;
      scene.observations.push_back({k, point, z, optim::levelInformation(1.2, octave)});
      scene.isOutlier.push_back(outlier);
    }
  }
  return scene;
}

// One pose observing `observations` exact, fixed points; the start is a constant-velocity-like
// prediction off by ~2 cm and ~0.5°.
inline SlamScene makeMotionOnlyScene(int observations, double stereoFraction, double outlierFraction,
                                     unsigned seed) {
  SlamSceneSpec spec;
  spec.keyframes = 1;
  spec.points = observations;
  spec.minObservationsPerPoint = 1;
  spec.maxObservationsPerPoint = 1;
  spec.stereoFraction = stereoFraction;
  spec.outlierFraction = outlierFraction;
  spec.fixedKeyframes = 0;
  spec.poseNoiseRotation = 0.01;
  spec.poseNoiseTranslation = 0.02;
  spec.pointNoise = 0.0;
  spec.seed = seed;
  SlamScene scene = makeSlamScene(spec);
  scene.initialPoints = scene.truePoints;
  return scene;
}

}  // namespace orbis::bench
