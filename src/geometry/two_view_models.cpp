// Homography and fundamental matrix: normalised linear fits and their χ²-gated scores
// (ORB-SLAM §IV-2, Hartley & Zisserman §4.4 and §11.2).
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "two_view_detail.hpp"

namespace orbis::two_view_detail {
namespace {

using Matrix9 = Eigen::Matrix<double, 9, 9>;
using Vector9 = Eigen::Matrix<double, 9, 1>;

// χ² 95% gates: 2 DoF for a point-to-point transfer (H), 1 DoF for a point-to-line distance
// (F); both scored against the 2-DoF gate so a model's score does not favour F for having
// fewer constraints per point (ORB-SLAM §IV-2).
constexpr double kHomographyGate = 5.991;
constexpr double kFundamentalGate = 3.841;
constexpr double kScoreThreshold = 5.991;

Eigen::Matrix3d normalisingTransform(const std::vector<Eigen::Vector2d>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= double(points.size());
  Eigen::Vector2d meanDeviation = Eigen::Vector2d::Zero();
  for (const auto& p : points) meanDeviation += (p - mean).cwiseAbs();
  meanDeviation /= double(points.size());
  // Identical coordinates on an axis (degenerate input): leave that axis unscaled.
  const double sx = meanDeviation.x() > 0 ? 1.0 / meanDeviation.x() : 1.0;
  const double sy = meanDeviation.y() > 0 ? 1.0 / meanDeviation.y() : 1.0;
  Eigen::Matrix3d T;
  T << sx, 0, -mean.x() * sx, 0, sy, -mean.y() * sy, 0, 0, 1;
  return T;
}

std::vector<Eigen::Vector2d> applyTransform(const Eigen::Matrix3d& T, std::vector<Eigen::Vector2d> points) {
  for (auto& p : points) p = T.topLeftCorner<2, 2>() * p + T.topRightCorner<2, 1>();
  return points;
}

// The unit vector minimising |A·h| over the rows accumulated in AᵀA: the eigenvector of the
// smallest eigenvalue. The normal equations keep the system 9×9 and fixed-size whatever the
// number of points; on Hartley-normalised coordinates their conditioning is harmless.
Vector9 smallestEigenvector(const Matrix9& normalEquations) {
  Eigen::SelfAdjointEigenSolver<Matrix9> solver(normalEquations);
  return solver.eigenvectors().col(0);  // eigenvalues come sorted ascending
}

Eigen::Matrix3d asMatrix(const Vector9& h) {
  Eigen::Matrix3d M;
  M << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return M;
}

// Adds one side's gated χ² to the score; returns whether it stayed inside the gate.
bool addGated(double chiSquare, double gate, double& score) {
  if (!(chiSquare <= gate)) return false;  // also rejects NaN
  score += kScoreThreshold - chiSquare;
  return true;
}

double squaredDistanceToLine(const Eigen::Vector3d& line, const Eigen::Vector2d& p) {
  const double normal2 = line.head<2>().squaredNorm();
  if (normal2 <= 0) return std::numeric_limits<double>::infinity();
  const double residual = line.x() * p.x() + line.y() * p.y() + line.z();
  return residual * residual / normal2;
}

double squaredTransferError(const Eigen::Matrix3d& H, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const Eigen::Vector3d mapped = H * from.homogeneous();
  if (mapped.z() == 0) return std::numeric_limits<double>::infinity();
  return (mapped.hnormalized() - to).squaredNorm();
}

}  // namespace

NormalisedMatches normaliseMatches(std::span<const TwoViewMatch> matches) {
  NormalisedMatches n;
  n.first.reserve(matches.size());
  n.second.reserve(matches.size());
  for (const auto& m : matches) {
    n.first.push_back(m.first);
    n.second.push_back(m.second);
  }
  n.firstTransform = normalisingTransform(n.first);
  n.secondTransform = normalisingTransform(n.second);
  n.first = applyTransform(n.firstTransform, std::move(n.first));
  n.second = applyTransform(n.secondTransform, std::move(n.second));
  return n;
}

Eigen::Matrix3d fitHomography(const NormalisedMatches& n, std::span<const int> indices) {
  Matrix9 normalEquations = Matrix9::Zero();
  for (const int i : indices) {
    const double u1 = n.first[i].x(), v1 = n.first[i].y();
    const double u2 = n.second[i].x(), v2 = n.second[i].y();
    Vector9 row;
    row << 0, 0, 0, -u1, -v1, -1, v2 * u1, v2 * v1, v2;
    normalEquations.selfadjointView<Eigen::Lower>().rankUpdate(row);
    row << u1, v1, 1, 0, 0, 0, -u2 * u1, -u2 * v1, -u2;
    normalEquations.selfadjointView<Eigen::Lower>().rankUpdate(row);
  }
  normalEquations = normalEquations.selfadjointView<Eigen::Lower>();
  const Eigen::Matrix3d normalisedH = asMatrix(smallestEigenvector(normalEquations));
  return n.secondTransform.inverse() * normalisedH * n.firstTransform;
}

Eigen::Matrix3d fitFundamental(const NormalisedMatches& n, std::span<const int> indices) {
  Matrix9 normalEquations = Matrix9::Zero();
  for (const int i : indices) {
    const double u1 = n.first[i].x(), v1 = n.first[i].y();
    const double u2 = n.second[i].x(), v2 = n.second[i].y();
    Vector9 row;
    row << u2 * u1, u2 * v1, u2, v2 * u1, v2 * v1, v2, u1, v1, 1;
    normalEquations.selfadjointView<Eigen::Lower>().rankUpdate(row);
  }
  normalEquations = normalEquations.selfadjointView<Eigen::Lower>();
  const Eigen::Matrix3d unconstrained = asMatrix(smallestEigenvector(normalEquations));
  // The closest rank-2 matrix (Frobenius norm): every epipolar line passes through the epipole.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(unconstrained, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d singular = svd.singularValues();
  singular.z() = 0;
  const Eigen::Matrix3d normalisedF = svd.matrixU() * singular.asDiagonal() * svd.matrixV().transpose();
  return n.secondTransform.transpose() * normalisedF * n.firstTransform;
}

ModelScore scoreHomography(const Eigen::Matrix3d& H21, std::span<const TwoViewMatch> matches) {
  ModelScore s;
  s.inliers.assign(matches.size(), false);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(H21);
  if (!lu.isInvertible()) return s;
  const Eigen::Matrix3d H12 = lu.inverse();
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const TwoViewMatch& m = matches[i];
    const bool inSecond = addGated(squaredTransferError(H21, m.first, m.second) / m.sigma2Second, kHomographyGate, s.score);
    const bool inFirst = addGated(squaredTransferError(H12, m.second, m.first) / m.sigma2First, kHomographyGate, s.score);
    s.inliers[i] = inFirst && inSecond;
    s.inlierCount += s.inliers[i] ? 1 : 0;
  }
  return s;
}

ModelScore scoreFundamental(const Eigen::Matrix3d& F21, std::span<const TwoViewMatch> matches) {
  ModelScore s;
  s.inliers.assign(matches.size(), false);
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const TwoViewMatch& m = matches[i];
    const Eigen::Vector3d lineInSecond = F21 * m.first.homogeneous();
    const Eigen::Vector3d lineInFirst = F21.transpose() * m.second.homogeneous();
    const bool inSecond =
        addGated(squaredDistanceToLine(lineInSecond, m.second) / m.sigma2Second, kFundamentalGate, s.score);
    const bool inFirst =
        addGated(squaredDistanceToLine(lineInFirst, m.first) / m.sigma2First, kFundamentalGate, s.score);
    s.inliers[i] = inFirst && inSecond;
    s.inlierCount += s.inliers[i] ? 1 : 0;
  }
  return s;
}

}  // namespace orbis::two_view_detail
