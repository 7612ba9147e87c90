// orbis/optim/bal_problem.hpp — a "Bundle Adjustment in the Large" problem as plain data.
//
// Contract: the contents of a BAL problem file (problem-*.txt): cameras of 9 parameters
// (angle-axis rotation ω, translation t, focal length f, radial k1, k2), 3-D points, and
// observations "camera point x y". BAL's camera model: P = R·X + t, p = −P.xy/P.z,
// pixel = f·(1 + k1‖p‖² + k2‖p‖⁴)·p, pixels measured from the image centre. It lives in optim,
// which solves and exports it (optim/bal.hpp); reading and writing the file is io's
// (io/bal.hpp), so the solver needs no file code.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace orbis {

// One BAL observation: camera and point indices and the measured pixel.
struct BalObservation {
  // @{
  // Camera index, point index and pixel coordinates.
  int camera = 0;
  int point = 0;
  double x = 0.0;
  double y = 0.0;
  // @}
};

// A BAL problem: cameras, points and observations.
struct BalProblem {
  using Camera = Eigen::Matrix<double, 9, 1>;  // ω (3), t (3), f, k1, k2
  // @{
  // Cameras, points and observations.
  std::vector<Camera> cameras;
  std::vector<Eigen::Vector3d> points;
  std::vector<BalObservation> observations;
  // @}
};

}  // namespace orbis
