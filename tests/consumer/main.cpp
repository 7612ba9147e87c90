// Uses the installed orbis package as a user would: prints the version (compiled part of the
// library), instantiates camera models and Lie groups (header part) and checks round trips.
#include <cmath>
#include <cstdio>

#include "orbis/camera/camera_model.hpp"
#include "orbis/geometry/se3.hpp"
#include "orbis/geometry/sim3.hpp"
#include "orbis/version.hpp"

int main() {
  std::printf("orbis %s found through find_package\n", orbis::versionString());

  const orbis::PinholeCamera<double> pinhole{517.3, 516.5, 318.6, 255.3, 640, 480};
  const orbis::RectifiedStereoCamera<double> stereo{pinhole, 0.11};
  static_assert(orbis::CameraModel<orbis::RectifiedStereoCamera<double>>);

  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.1, -0.2, 0.3, 0.05, -0.1, 0.2;
  const orbis::SE3<double> pose = orbis::SE3<double>::exp(xi);  // world -> camera
  const Eigen::Vector3d pw(0.4, -0.3, 3.0);
  const Eigen::Vector3d pc = pose * pw;
  const Eigen::Vector3d obs = stereo.project(pc);
  const Eigen::Vector3d back = pose.inverse() * stereo.unproject(obs);
  const double logError = (pose.log() - xi).norm();

  const orbis::Sim3<double> sim(2.0, pose.so3(), pose.translation());
  const double simError = ((sim.inverse() * (sim * pw)) - pw).norm();

  std::printf("stereo observation (uL, v, uR) = (%.3f, %.3f, %.3f), bf %.3f\n", obs.x(), obs.y(), obs.z(),
              stereo.bf());
  std::printf("round trips: point %.2e m, SE3 log(exp) %.2e, Sim3 inverse %.2e\n", (back - pw).norm(), logError,
              simError);
  const bool ok = (back - pw).norm() < 1e-9 && logError < 1e-12 && simError < 1e-12;
  std::printf("%s\n", ok ? "consumer OK" : "consumer FAILED");
  return ok ? 0 : 1;
}
