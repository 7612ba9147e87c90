// Refinement of the chosen motion on the essential manifold: Levenberg–Marquardt on the
// Sampson distance of every inlier. The linear fits minimise an algebraic error that is badly
// biased when the camera moves sideways (the epipole far outside the image: the forward
// component of t is then barely constrained). Measured on a sideways motion of 0.6 m before a
// scene 4-10 m deep (0.5 px noise, 20% wrong matches, three seeds): the RANSAC F was 2.5-9° off
// in translation direction, refined 0.7-1.25°, against 0.35-0.52° for the same refinement on
// exactly the true inliers (a wrong match inside the 1.96 px gate still pulls). Five parameters
// (rotation increment, two tangent directions of the unit translation) and numeric Jacobians:
// it runs once per initialisation attempt.
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "two_view_detail.hpp"

namespace orbis::two_view_detail {
namespace {

using Vector5 = Eigen::Matrix<double, 5, 1>;
using Matrix5 = Eigen::Matrix<double, 5, 5>;

// Huber threshold on the normalised Sampson distance: the 1-DoF χ² gate the inliers passed.
constexpr double kHuberDelta = 1.96;  // √3.841

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// Two unit vectors orthogonal to t and to each other: the tangent plane of the unit sphere.
Eigen::Matrix<double, 3, 2> tangentBasis(const Eigen::Vector3d& t) {
  const Eigen::Vector3d helper = std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d b1 = t.cross(helper).normalized();
  Eigen::Matrix<double, 3, 2> B;
  B << b1, t.cross(b1);
  return B;
}

MotionHypothesis perturb(const MotionHypothesis& m, const Vector5& delta) {
  const Eigen::Vector3d omega = delta.head<3>();
  const double angle = omega.norm();
  const Eigen::Matrix3d dR =
      angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t = (m.translation + tangentBasis(m.translation) * delta.tail<2>()).normalized();
  return {m.rotation * dR, t};
}

struct SampsonProblem {
  std::span<const TwoViewMatch> matches;
  const std::vector<int>& indices;
  Eigen::Matrix3d Kinv;

  // Sampson distance of each inlier in σ units of its own level.
  Eigen::VectorXd residuals(const MotionHypothesis& m) const {
    const Eigen::Matrix3d F = Kinv.transpose() * skew(m.translation) * m.rotation * Kinv;  // fundamentalOf
    Eigen::VectorXd r(indices.size());
    for (std::size_t k = 0; k < indices.size(); ++k) {
      const TwoViewMatch& match = matches[indices[k]];
      const Eigen::Vector3d x1 = match.first.homogeneous(), x2 = match.second.homogeneous();
      const Eigen::Vector3d Fx1 = F * x1, Ftx2 = F.transpose() * x2;
      const double denominator = Fx1.head<2>().squaredNorm() + Ftx2.head<2>().squaredNorm();
      const double sigma = std::sqrt(0.5 * (match.sigma2First + match.sigma2Second));
      r(k) = denominator > 0 ? x2.dot(Fx1) / std::sqrt(denominator) / sigma : 0.0;
    }
    return r;
  }
};

double robustCost(const Eigen::VectorXd& r) {
  double cost = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    const double a = std::abs(r(i));
    cost += a <= kHuberDelta ? a * a : 2 * kHuberDelta * a - kHuberDelta * kHuberDelta;
  }
  return cost;
}

Eigen::VectorXd huberWeights(const Eigen::VectorXd& r) {
  Eigen::VectorXd w(r.size());
  for (Eigen::Index i = 0; i < r.size(); ++i) w(i) = std::abs(r(i)) <= kHuberDelta ? 1.0 : kHuberDelta / std::abs(r(i));
  return w;
}

Eigen::Matrix<double, Eigen::Dynamic, 5> numericJacobian(const SampsonProblem& problem, const MotionHypothesis& m) {
  constexpr double kStep = 1e-6;
  Eigen::Matrix<double, Eigen::Dynamic, 5> J(Eigen::Index(problem.indices.size()), 5);
  for (int p = 0; p < 5; ++p) {
    Vector5 delta = Vector5::Zero();
    delta(p) = kStep;
    const Eigen::VectorXd plus = problem.residuals(perturb(m, delta));
    const Eigen::VectorXd minus = problem.residuals(perturb(m, -delta));
    J.col(p) = (plus - minus) / (2 * kStep);
  }
  return J;
}

}  // namespace

Eigen::Matrix3d fundamentalOf(const MotionHypothesis& motion, const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d Kinv = K.inverse();
  return Kinv.transpose() * skew(motion.translation) * motion.rotation * Kinv;
}

MotionHypothesis refineMotion(const MotionHypothesis& start, std::span<const TwoViewMatch> matches,
                              const std::vector<bool>& inliers, const Eigen::Matrix3d& K, int iterations) {
  std::vector<int> indices;
  for (std::size_t i = 0; i < inliers.size(); ++i) {
    if (inliers[i]) indices.push_back(int(i));
  }
  if (indices.size() < 5) return start;
  const SampsonProblem problem{matches, indices, K.inverse()};
  MotionHypothesis current = start;
  Eigen::VectorXd r = problem.residuals(current);
  double cost = robustCost(r);
  double lambda = 1e-3;
  for (int it = 0; it < iterations; ++it) {
    const Eigen::Matrix<double, Eigen::Dynamic, 5> J = numericJacobian(problem, current);
    const Eigen::VectorXd w = huberWeights(r);
    const Matrix5 H = J.transpose() * w.asDiagonal() * J;
    const Vector5 g = J.transpose() * w.asDiagonal() * r;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Matrix5 damped = H;
      damped.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      const Vector5 step = -damped.ldlt().solve(g);
      const MotionHypothesis candidate = perturb(current, step);
      const Eigen::VectorXd candidateResiduals = problem.residuals(candidate);
      const double candidateCost = robustCost(candidateResiduals);
      if (candidateCost < cost) {
        improved = true;
        current = candidate;
        r = candidateResiduals;
        const double relativeDecrease = (cost - candidateCost) / cost;
        cost = candidateCost;
        lambda = std::max(lambda / 10, 1e-9);
        if (relativeDecrease < 1e-10) return current;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  return current;
}

}  // namespace orbis::two_view_detail
