// tests/optim/test_scenes.hpp — a user-defined residual and a seeded synthetic scene for the
// engine tests that need no Lie group: cameras that only translate (the pose is the camera
// centre in R³), looking down +z with a pinhole of focal length f.
#pragma once

#include "orbis/optim/manifold.hpp"
#include "orbis/optim/problem.hpp"

#include <Eigen/Core>

#include <random>
#include <vector>

namespace orbis::optim::test {

struct TranslatingCameraResidual {
  using PoseManifold = EuclideanManifold<3>;
  static constexpr int kDim = 2;
  static constexpr bool kHasPoint = true;
  Eigen::Vector2d measurement;
  double focal = 500.0;

  void evaluate(const Eigen::Vector3d& centre, const Eigen::Vector3d& point, Eigen::Vector2d& r,
                Eigen::Matrix<double, 2, 3>* jCentre, Eigen::Matrix<double, 2, 3>* jPoint) const {
    const Eigen::Vector3d p = point - centre;
    const double invZ = 1.0 / p.z();
    r = focal * p.head<2>() * invZ - measurement;
    if (jCentre || jPoint) {
      Eigen::Matrix<double, 2, 3> d;
      d << focal * invZ, 0.0, -focal * p.x() * invZ * invZ,
           0.0, focal * invZ, -focal * p.y() * invZ * invZ;
      if (jCentre) *jCentre = -d;
      if (jPoint) *jPoint = d;
    }
  }
};

struct TranslatingScene {
  std::vector<Eigen::Vector3d> centres, points;
  struct Observation { int camera, point; Eigen::Vector2d pixel; bool outlier; };
  std::vector<Observation> observations;
};

// Cameras on a line at z = 0, points in a slab 4–8 m ahead; every camera sees every point.
inline TranslatingScene makeTranslatingScene(int cameras, int points, double noisePx,
                                             double outlierFraction, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noisePx);
  TranslatingScene scene;
  for (int c = 0; c < cameras; ++c) scene.centres.emplace_back(0.3 * c, 0.05 * uni(rng), 0.0);
  for (int p = 0; p < points; ++p) scene.points.emplace_back(3 * uni(rng), 2 * uni(rng), 6 + 2 * uni(rng));
  TranslatingCameraResidual model;
  for (int c = 0; c < cameras; ++c) {
    for (int p = 0; p < points; ++p) {
      Eigen::Vector2d r;
      model.measurement.setZero();
      model.evaluate(scene.centres[c], scene.points[p], r, nullptr, nullptr);
      const bool outlier = (uni(rng) + 1.0) * 0.5 < outlierFraction;
      Eigen::Vector2d pixel = r + Eigen::Vector2d(noise(rng), noise(rng));
      if (outlier) pixel += Eigen::Vector2d(40 * uni(rng) + 40, 40 * uni(rng) - 40);
      scene.observations.push_back({c, p, pixel, outlier});
    }
  }
  return scene;
}

}  // namespace orbis::optim::test
