// Fisheye keypoints onto the tangent plane; see orbis/features/fisheye_features.hpp.
#include "orbis/features/fisheye_features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace orbis::detail {

void finishFisheye(FrameFeatures& f, const KannalaBrandtCamera<double>& lens, double maxAngle, int width,
                   int height) {
  const double minCos = std::cos(maxAngle);
  const PinholeCamera<double> plane = lens.centralPinhole();
  std::size_t kept = 0;
  f.keypointsUn.clear();
  for (std::size_t i = 0; i < f.keypoints.size(); ++i) {
    const Eigen::Vector3d ray = lens.bearing(Eigen::Vector2d(f.keypoints[i].u, f.keypoints[i].v));
    if (ray.z() < minCos) continue;  // beyond maxAngle: far out on the plane, its noise magnified
    const Eigen::Vector2d px = plane.project(ray);
    f.keypoints[kept] = f.keypoints[i];
    f.descriptors[kept] = f.descriptors[i];
    Keypoint un = f.keypoints[kept];
    un.u = static_cast<float>(px.x());
    un.v = static_cast<float>(px.y());
    f.keypointsUn.push_back(un);
    ++kept;
  }
  f.keypoints.resize(kept);
  f.descriptors.resize(kept);
  f.uRight.assign(kept, -1.f);
  f.depth.assign(kept, -1.f);
  // The grid covers where the image's border rays, pulled in to the cone of maxAngle, land.
  float minX = std::numeric_limits<float>::max(), maxX = std::numeric_limits<float>::lowest();
  float minY = minX, maxY = maxX;
  const auto add = [&](double u, double v) {
    Eigen::Vector3d ray = lens.bearing(Eigen::Vector2d(u, v));
    if (ray.z() < minCos) {
      const double sideways = std::hypot(ray.x(), ray.y());
      if (sideways <= 0) return;
      const double s = std::sin(maxAngle) / sideways;
      ray = Eigen::Vector3d(ray.x() * s, ray.y() * s, minCos);
    }
    const Eigen::Vector2d px = plane.project(ray);
    minX = std::min(minX, static_cast<float>(px.x()));
    maxX = std::max(maxX, static_cast<float>(px.x()));
    minY = std::min(minY, static_cast<float>(px.y()));
    maxY = std::max(maxY, static_cast<float>(px.y()));
  };
  constexpr int kSteps = 64;
  for (int k = 0; k <= kSteps; ++k) {
    const double a = static_cast<double>(k) / kSteps;
    add(a * width, 0), add(a * width, height), add(0, a * height), add(width, a * height);
  }
  f.grid.build(f.keypointsUn, minX, maxX, minY, maxY);
}

}  // namespace orbis::detail
