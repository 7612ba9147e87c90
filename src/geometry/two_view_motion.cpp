// Motion hypotheses from a homography (Faugeras & Lustman 1988, as ORB-SLAM uses it) or an
// essential matrix (Hartley & Zisserman §9.6.2), and the check that picks among them by
// triangulating every inlier (ORB-SLAM §IV-4).
#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "two_view_detail.hpp"

namespace orbis::two_view_detail {
namespace {

// Points seen under less parallax than this (≈0.36°) have no trustworthy depth: their sign may
// flip with noise, so cheirality is not asked of them (ORB-SLAM's 0.99998).
constexpr double kMinCosParallaxForDepth = 0.99998;
// Reprojection gate: χ² 4·σ², i.e. two standard deviations per pixel axis (ORB-SLAM's).
constexpr double kReprojectionChiSquare = 4.0;
// Singular values closer than this ratio count as equal (a degenerate homography).
constexpr double kDistinctSingularRatio = 1.00001;
// ORB-SLAM's parallax measure: the angle of the 51st most parallactic point (or the least
// parallactic one when fewer), robust to a few far outliers yet asking for many good points.
constexpr std::size_t kParallaxRank = 50;

MotionHypothesis makeHypothesis(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return {R, t.normalized()};
}

// The 8 solutions of the d' = +d₂ and d' = −d₂ cases for A = K⁻¹HK = U·diag(d₁,d₂,d₃)·Vᵀ.
void addFaugerasSolutions(const Eigen::Matrix3d& U, const Eigen::Matrix3d& V, double sign, const Eigen::Vector3d& d,
                          std::vector<MotionHypothesis>& out) {
  const double d1 = d(0), d2 = d(1), d3 = d(2);
  const double a1 = std::sqrt((d1 * d1 - d2 * d2) / (d1 * d1 - d3 * d3));
  const double a3 = std::sqrt((d2 * d2 - d3 * d3) / (d1 * d1 - d3 * d3));
  const double x1[4] = {a1, a1, -a1, -a1};
  const double x3[4] = {a3, -a3, a3, -a3};
  const double cross = std::sqrt((d1 * d1 - d2 * d2) * (d2 * d2 - d3 * d3));

  const double sinTheta = cross / ((d1 + d3) * d2);  // d' = +d₂
  const double cosTheta = (d2 * d2 + d1 * d3) / ((d1 + d3) * d2);
  const double thetaSigns[4] = {1, -1, -1, 1};
  for (int i = 0; i < 4; ++i) {
    const double s = sinTheta * thetaSigns[i];
    Eigen::Matrix3d Rp;
    Rp << cosTheta, 0, -s, 0, 1, 0, s, 0, cosTheta;
    const Eigen::Vector3d tp = Eigen::Vector3d(x1[i], 0, -x3[i]) * (d1 - d3);
    out.push_back(makeHypothesis(sign * U * Rp * V.transpose(), U * tp));
  }
  const double sinPhi = cross / ((d1 - d3) * d2);  // d' = −d₂
  const double cosPhi = (d1 * d3 - d2 * d2) / ((d1 - d3) * d2);
  for (int i = 0; i < 4; ++i) {
    const double s = sinPhi * thetaSigns[i];
    Eigen::Matrix3d Rp;
    Rp << cosPhi, 0, s, 0, -1, 0, s, 0, -cosPhi;
    const Eigen::Vector3d tp = Eigen::Vector3d(x1[i], 0, x3[i]) * (d1 + d3);
    out.push_back(makeHypothesis(sign * U * Rp * V.transpose(), U * tp));
  }
}

// Linear triangulation (DLT) from the two projection matrices K[I|0] and K[R|t].
Eigen::Vector3d triangulate(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Matrix<double, 3, 4>& P1,
                            const Eigen::Matrix<double, 3, 4>& P2) {
  Eigen::Matrix4d A;
  A.row(0) = p1.x() * P1.row(2) - P1.row(0);
  A.row(1) = p1.y() * P1.row(2) - P1.row(1);
  A.row(2) = p2.x() * P2.row(2) - P2.row(0);
  A.row(3) = p2.y() * P2.row(2) - P2.row(1);
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  return X.hnormalized();
}

double squaredReprojectionError(const Eigen::Matrix3d& K, const Eigen::Vector3d& pointInCamera,
                                const Eigen::Vector2d& observed) {
  return ((K * pointInCamera).hnormalized() - observed).squaredNorm();
}

}  // namespace

std::vector<MotionHypothesis> homographyMotions(const Eigen::Matrix3d& H21, const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d A = K.inverse() * H21 * K;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  if (!(d(0) / d(1) >= kDistinctSingularRatio && d(1) / d(2) >= kDistinctSingularRatio)) return {};
  const double sign = svd.matrixU().determinant() * svd.matrixV().determinant();
  std::vector<MotionHypothesis> motions;
  motions.reserve(8);
  addFaugerasSolutions(svd.matrixU(), svd.matrixV(), sign, d, motions);
  return motions;
}

std::vector<MotionHypothesis> essentialMotions(const Eigen::Matrix3d& F21, const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d E = K.transpose() * F21 * K;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Matrix3d W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  // E is defined up to sign, so a rotation with determinant −1 is negated into SO(3).
  auto properRotation = [](Eigen::Matrix3d R) { return R.determinant() < 0 ? Eigen::Matrix3d(-R) : R; };
  const Eigen::Matrix3d R1 = properRotation(U * W * V.transpose());
  const Eigen::Matrix3d R2 = properRotation(U * W.transpose() * V.transpose());
  const Eigen::Vector3d t = U.col(2);
  return {makeHypothesis(R1, t), makeHypothesis(R2, t), makeHypothesis(R1, -t), makeHypothesis(R2, -t)};
}

MotionCheck checkMotion(const MotionHypothesis& motion, std::span<const TwoViewMatch> matches,
                        const std::vector<bool>& inliers, const Eigen::Matrix3d& K) {
  MotionCheck check;
  check.points.assign(matches.size(), Eigen::Vector3d::Zero());
  check.triangulated.assign(matches.size(), false);
  Eigen::Matrix<double, 3, 4> P1 = Eigen::Matrix<double, 3, 4>::Zero();
  P1.leftCols<3>() = K;
  Eigen::Matrix<double, 3, 4> P2;
  P2 << K * motion.rotation, K * motion.translation;
  const Eigen::Vector3d secondCentre = -motion.rotation.transpose() * motion.translation;

  std::vector<double> cosParallaxes;
  cosParallaxes.reserve(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (!inliers[i]) continue;
    const TwoViewMatch& m = matches[i];
    const Eigen::Vector3d X = triangulate(m.first, m.second, P1, P2);
    if (!X.allFinite()) continue;
    const Eigen::Vector3d inSecond = motion.rotation * X + motion.translation;
    const Eigen::Vector3d ray1 = X, ray2 = X - secondCentre;
    const double cosParallax = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
    const bool depthTrusted = cosParallax < kMinCosParallaxForDepth;
    if (depthTrusted && (X.z() <= 0 || inSecond.z() <= 0)) continue;
    if (squaredReprojectionError(K, X, m.first) > kReprojectionChiSquare * m.sigma2First) continue;
    if (squaredReprojectionError(K, inSecond, m.second) > kReprojectionChiSquare * m.sigma2Second) continue;
    ++check.good;
    cosParallaxes.push_back(cosParallax);
    check.points[i] = X;
    check.triangulated[i] = depthTrusted;
  }
  if (!cosParallaxes.empty()) {
    std::sort(cosParallaxes.begin(), cosParallaxes.end());
    const double cosAtRank = cosParallaxes[std::min(kParallaxRank, cosParallaxes.size() - 1)];
    check.parallaxDeg = std::acos(std::clamp(cosAtRank, -1.0, 1.0)) * 180.0 / std::numbers::pi;
  }
  return check;
}

}  // namespace orbis::two_view_detail
