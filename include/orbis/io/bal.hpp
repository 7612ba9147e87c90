// orbis/io/bal.hpp — "Bundle Adjustment in the Large" problem files (problem-*.txt).
//
// Contract: the BAL text layout — a header "cameras points observations", then one line per
// observation "camera point x y", then 9 numbers per camera (angle-axis rotation, translation,
// focal length, k1, k2) and 3 per point, whitespace-separated. BAL's camera model: P = R·X + t,
// p = −P.xy/P.z, pixel = f·(1 + k1‖p‖² + k2‖p‖⁴)·p, pixels measured from the image centre.
// readBal throws orbis::Error naming the file and line on malformed input or out-of-range
// indices; writeBal writes the same layout with round-trip precision.
#pragma once

#include <Eigen/Core>

#include <filesystem>
#include <vector>

namespace orbis {

struct BalObservation {
  int camera = 0;
  int point = 0;
  double x = 0.0;
  double y = 0.0;
};

struct BalProblem {
  using Camera = Eigen::Matrix<double, 9, 1>;  // ω (3), t (3), f, k1, k2
  std::vector<Camera> cameras;
  std::vector<Eigen::Vector3d> points;
  std::vector<BalObservation> observations;
};

BalProblem readBal(const std::filesystem::path& file);
void writeBal(const std::filesystem::path& file, const BalProblem& problem);

}  // namespace orbis
