#include "orbis/loop/relative_pose.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace orbis::loop {

namespace {

Eigen::Matrix<double, 2, 3> projectionJacobian(const TwoWayReprojection& c, const Eigen::Vector3d& q) {
  const double invZ = 1.0 / q.z(), invZ2 = invZ * invZ;
  Eigen::Matrix<double, 2, 3> J;
  J << c.fx * invZ, 0, -c.fx * q.x() * invZ2,  //
      0, c.fy * invZ, -c.fy * q.y() * invZ2;
  return J;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

struct PairChi2 {
  double chi2First = 0, chi2Second = 0;
  bool valid = false;
};

PairChi2 pairChi2(const TwoWayReprojection& model, const SE3d& T12, const PointPair& pair) {
  Eigen::Matrix<double, 4, 1> r;
  PairChi2 out;
  if (!model.evaluate(T12, pair, r, nullptr)) return out;
  out.chi2First = r.head<2>().squaredNorm() * pair.information1;
  out.chi2Second = r.tail<2>().squaredNorm() * pair.information2;
  out.valid = true;
  return out;
}

// Flags the pairs within `chi2` in both images (only among those already flagged when
// `keepOutliersOut`); returns how many.
int classify(const std::vector<PointPair>& pairs, const TwoWayReprojection& model, const SE3d& T12, double chi2,
             bool keepOutliersOut, std::vector<char>& inliers) {
  int count = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (keepOutliersOut && !inliers[k]) continue;
    const PairChi2 c = pairChi2(model, T12, pairs[k]);
    inliers[k] = c.valid && c.chi2First < chi2 && c.chi2Second < chi2;
    count += inliers[k];
  }
  return count;
}

// Gauss-Newton with a Huber kernel (threshold √outlierChi2 in σ units) on the flagged pairs.
void gaussNewton(const std::vector<PointPair>& pairs, const TwoWayReprojection& model, SE3d& T12,
                 const std::vector<char>& use, double huberChi2, int iterations) {
  const double delta = std::sqrt(huberChi2);
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      if (!use[k]) continue;
      Eigen::Matrix<double, 4, 1> r;
      Eigen::Matrix<double, 4, 6> J;
      if (!model.evaluate(T12, pairs[k], r, &J)) continue;
      const double info[2] = {pairs[k].information1, pairs[k].information2};
      for (int half = 0; half < 2; ++half) {
        const auto rh = r.segment<2>(2 * half);
        const auto Jh = J.middleRows<2>(2 * half);
        const double e = std::sqrt(rh.squaredNorm() * info[half]);
        const double w = info[half] * (e <= delta ? 1.0 : delta / e);
        H.noalias() += w * Jh.transpose() * Jh;
        g.noalias() += w * Jh.transpose() * rh;
      }
    }
    // r = obs − π: the step minimising ‖r + Jδ‖² is −H⁻¹Jᵀr.
    const Eigen::Matrix<double, 6, 1> step = -H.ldlt().solve(g);
    if (!step.allFinite()) return;
    T12 = SE3d::exp(step) * T12;
    if (step.norm() < 1e-10) return;
  }
}

}  // namespace

bool TwoWayReprojection::evaluate(const SE3d& T12, const PointPair& pair, Eigen::Matrix<double, 4, 1>& r,
                                  Eigen::Matrix<double, 4, 6>* J) const {
  const SE3d T21 = T12.inverse();
  const Eigen::Vector3d q1 = T12 * pair.p2;  // point 2 seen by camera 1
  const Eigen::Vector3d q2 = T21 * pair.p1;  // point 1 seen by camera 2
  if (q1.z() <= 0 || q2.z() <= 0) return false;
  r(0) = pair.obs1.x() - (fx * q1.x() / q1.z() + cx);
  r(1) = pair.obs1.y() - (fy * q1.y() / q1.z() + cy);
  r(2) = pair.obs2.x() - (fx * q2.x() / q2.z() + cx);
  r(3) = pair.obs2.y() - (fy * q2.y() / q2.z() + cy);
  if (J) {
    // q1 = exp(δ)·T12·p2 → ∂q1/∂δ = [I, −[q1]×]; q2 = T21·exp(−δ)·p1 → ∂q2/∂δ = −R21·[I, −[p1]×].
    Eigen::Matrix<double, 3, 6> dq1, dq2;
    dq1 << Eigen::Matrix3d::Identity(), -skew(q1);
    dq2 << Eigen::Matrix3d::Identity(), -skew(pair.p1);
    dq2 = -T21.rotationMatrix() * dq2;
    J->topRows<2>() = -projectionJacobian(*this, q1) * dq1;
    J->bottomRows<2>() = -projectionJacobian(*this, q2) * dq2;
  }
  return true;
}

SE3d alignPoints(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target) {
  const Eigen::Matrix4d T = Eigen::umeyama(source, target, false);
  return SE3d::fromMatrix(T);
}

RelativePoseEstimate estimateRelativePoseRansac(const std::vector<PointPair>& pairs, const TwoWayReprojection& model,
                                                const RelativePoseRansacOptions& options, std::mt19937& rng) {
  RelativePoseEstimate best;
  const std::size_t n = pairs.size();
  if (n < 3 || static_cast<int>(n) < options.minInliers) return best;
  std::vector<char> inliers(n);
  for (int it = 0; it < options.iterations; ++it) {
    // Three distinct indices; rng() % n keeps the draw identical on every standard library.
    std::size_t idx[3];
    idx[0] = rng() % n;
    do idx[1] = rng() % n; while (idx[1] == idx[0]);
    do idx[2] = rng() % n; while (idx[2] == idx[0] || idx[2] == idx[1]);
    Eigen::Matrix3d source, target;
    for (int c = 0; c < 3; ++c) {
      source.col(c) = pairs[idx[c]].p2;
      target.col(c) = pairs[idx[c]].p1;
    }
    // A degenerate (near-collinear) triple gives no rotation.
    const Eigen::Vector3d e1 = source.col(1) - source.col(0), e2 = source.col(2) - source.col(0);
    if (e1.cross(e2).norm() < 1e-6 * e1.norm() * e2.norm() + 1e-12) continue;
    const SE3d T = alignPoints(source, target);
    const int count = classify(pairs, model, T, options.inlierChi2, false, inliers);
    if (count > best.inlierCount) {
      best.inlierCount = count;
      best.T12 = T;
      best.inliers = inliers;
    }
  }
  if (best.inlierCount < options.minInliers || best.inlierCount < 3) return RelativePoseEstimate{};
  // Re-estimate from every inlier, then re-classify.
  Eigen::Matrix3Xd source(3, best.inlierCount), target(3, best.inlierCount);
  for (std::size_t k = 0, c = 0; k < n; ++k) {
    if (!best.inliers[k]) continue;
    source.col(static_cast<long>(c)) = pairs[k].p2;
    target.col(static_cast<long>(c)) = pairs[k].p1;
    ++c;
  }
  const SE3d refined = alignPoints(source, target);
  const int count = classify(pairs, model, refined, options.inlierChi2, false, inliers);
  if (count >= best.inlierCount) {
    best.T12 = refined;
    best.inliers = inliers;
    best.inlierCount = count;
  }
  best.found = true;
  return best;
}

int refineRelativePose(const std::vector<PointPair>& pairs, const TwoWayReprojection& model, SE3d& T12,
                       std::vector<char>& inliers, double outlierChi2) {
  inliers.resize(pairs.size(), 0);
  gaussNewton(pairs, model, T12, inliers, outlierChi2, 5);
  if (classify(pairs, model, T12, outlierChi2, true, inliers) >= 3) gaussNewton(pairs, model, T12, inliers, outlierChi2, 10);
  return classify(pairs, model, T12, outlierChi2, true, inliers);
}

}  // namespace orbis::loop
