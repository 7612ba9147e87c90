// EPnP and its RANSAC (declared in tracking/relocaliser.hpp): pinhole geometry, no map types.
#include "orbis/tracking/relocaliser.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace orbis {

namespace {

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix6x10d = Eigen::Matrix<double, 6, 10>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// The six pairs of control points whose distances EPnP preserves.
constexpr std::array<std::array<int, 2>, 6> kPairs{{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};

// Least-squares rotation and translation taking `from` onto `to` (Horn/Kabsch, no scale).
SE3d alignRigid(const Vector3dList& from, const Vector3dList& to) {
  Eigen::Vector3d cf = Eigen::Vector3d::Zero(), ct = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    cf += from[i];
    ct += to[i];
  }
  cf /= static_cast<double>(from.size());
  ct /= static_cast<double>(to.size());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) H += (to[i] - ct) * (from[i] - cf).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  if ((U * V.transpose()).determinant() < 0) U.col(2) = -U.col(2);
  const Eigen::Matrix3d R = U * V.transpose();
  return SE3d(R, ct - R * cf);
}

double reprojectionError(const Vector3dList& world, const Vector2dList& pixels, const PinholeCamera<double>& K,
                         const SE3d& Tcw) {
  double sum = 0;
  for (std::size_t i = 0; i < world.size(); ++i) {
    const Eigen::Vector3d pc = Tcw * world[i];
    const Eigen::Vector2d uv = K.project(pc);
    sum += std::hypot(uv.x() - pixels[i].x(), uv.y() - pixels[i].y());
  }
  return sum / static_cast<double>(world.size());
}

// Gauss-Newton on the betas: the control points' camera-frame distances must match the world ones.
void refineBetas(const Matrix6x10d& L, const Vector6d& rho, Eigen::Vector4d& b) {
  for (int iteration = 0; iteration < 5; ++iteration) {
    Eigen::Matrix<double, 6, 4> J;
    Vector6d r;
    for (int k = 0; k < 6; ++k) {
      const auto l = L.row(k);
      J(k, 0) = 2 * l(0) * b(0) + l(1) * b(1) + l(3) * b(2) + l(6) * b(3);
      J(k, 1) = l(1) * b(0) + 2 * l(2) * b(1) + l(4) * b(2) + l(7) * b(3);
      J(k, 2) = l(3) * b(0) + l(4) * b(1) + 2 * l(5) * b(2) + l(8) * b(3);
      J(k, 3) = l(6) * b(0) + l(7) * b(1) + l(8) * b(2) + 2 * l(9) * b(3);
      const double predicted = l(0) * b(0) * b(0) + l(1) * b(0) * b(1) + l(2) * b(1) * b(1) + l(3) * b(0) * b(2) +
                               l(4) * b(1) * b(2) + l(5) * b(2) * b(2) + l(6) * b(0) * b(3) + l(7) * b(1) * b(3) +
                               l(8) * b(2) * b(3) + l(9) * b(3) * b(3);
      r(k) = rho(k) - predicted;
    }
    b += J.colPivHouseholderQr().solve(r);
  }
}

}  // namespace

bool solveEpnp(const Vector3dList& world, const Vector2dList& pixels, const PinholeCamera<double>& K, SE3d& Tcw) {
  const std::size_t n = world.size();
  if (n < 4 || pixels.size() != n) return false;

  // Control points: the centroid and the principal axes of the world points.
  std::array<Eigen::Vector3d, 4> cw;
  cw[0] = Eigen::Vector3d::Zero();
  for (const auto& p : world) cw[0] += p;
  cw[0] /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : world) cov += (p - cw[0]) * (p - cw[0]).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(cov);
  for (int k = 0; k < 3; ++k) {
    const double extent = std::sqrt(std::max(pca.eigenvalues()(k), 0.0) / static_cast<double>(n));
    cw[static_cast<std::size_t>(k) + 1] = cw[0] + extent * pca.eigenvectors().col(k);
  }
  Eigen::Matrix3d C;
  for (int k = 0; k < 3; ++k) C.col(k) = cw[static_cast<std::size_t>(k) + 1] - cw[0];
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(C);
  if (!lu.isInvertible()) return false;
  const Eigen::Matrix3d Cinv = lu.inverse();

  // Barycentric coordinates, and M (2n x 12) whose null space holds the camera control points.
  std::vector<Eigen::Vector4d, Eigen::aligned_allocator<Eigen::Vector4d>> alphas(n);
  Matrix12d MtM = Matrix12d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = Cinv * (world[i] - cw[0]);
    alphas[i] << 1 - a.sum(), a(0), a(1), a(2);
    Eigen::Matrix<double, 2, 12> rows = Eigen::Matrix<double, 2, 12>::Zero();
    for (int j = 0; j < 4; ++j) {
      const double aj = alphas[i](j);
      rows(0, 3 * j) = aj * K.fx;
      rows(0, 3 * j + 2) = aj * (K.cx - pixels[i].x());
      rows(1, 3 * j + 1) = aj * K.fy;
      rows(1, 3 * j + 2) = aj * (K.cy - pixels[i].y());
    }
    MtM.noalias() += rows.transpose() * rows;
  }
  Eigen::SelfAdjointEigenSolver<Matrix12d> eig(MtM);
  std::array<Vector12d, 4> v;  // v[0]: eigenvector of the smallest eigenvalue
  for (int k = 0; k < 4; ++k) v[static_cast<std::size_t>(k)] = eig.eigenvectors().col(k);

  Matrix6x10d L;
  Vector6d rho;
  for (std::size_t r = 0; r < kPairs.size(); ++r) {
    const int a = kPairs[r][0], b = kPairs[r][1];
    std::array<Eigen::Vector3d, 4> d;
    for (std::size_t k = 0; k < 4; ++k) d[k] = v[k].segment<3>(3 * a) - v[k].segment<3>(3 * b);
    const auto ri = static_cast<Eigen::Index>(r);
    L.row(ri) << d[0].dot(d[0]), 2 * d[0].dot(d[1]), d[1].dot(d[1]), 2 * d[0].dot(d[2]), 2 * d[1].dot(d[2]),
        d[2].dot(d[2]), 2 * d[0].dot(d[3]), 2 * d[1].dot(d[3]), 2 * d[2].dot(d[3]), d[3].dot(d[3]);
    rho(ri) = (cw[static_cast<std::size_t>(a)] - cw[static_cast<std::size_t>(b)]).squaredNorm();
  }

  auto solveColumns = [&](std::initializer_list<int> cols) {
    Eigen::MatrixXd A(6, static_cast<Eigen::Index>(cols.size()));
    Eigen::Index c = 0;
    for (int col : cols) A.col(c++) = L.col(col);
    return Eigen::VectorXd(A.colPivHouseholderQr().solve(rho));
  };
  std::array<Eigen::Vector4d, 3> betas;
  {  // N = 4 with products b00 b01 b02 b03
    const Eigen::VectorXd x = solveColumns({0, 1, 3, 6});
    Eigen::Vector4d& b = betas[0];
    const double s = x(0) < 0 ? -1 : 1;
    b(0) = std::sqrt(std::abs(x(0)));
    for (int k = 1; k < 4; ++k) b(k) = s * x(k) / b(0);
  }
  {  // N = 2 with b00 b01 b11
    const Eigen::VectorXd x = solveColumns({0, 1, 2});
    Eigen::Vector4d& b = betas[1];
    b.setZero();
    const bool negative = x(0) < 0;
    b(0) = std::sqrt(std::abs(x(0)));
    b(1) = (negative ? x(2) < 0 : x(2) > 0) ? std::sqrt(std::abs(x(2))) : 0.0;
    if (x(1) < 0) b(0) = -b(0);
  }
  {  // N = 3 with b00 b01 b11 b02 b12
    const Eigen::VectorXd x = solveColumns({0, 1, 2, 3, 4});
    Eigen::Vector4d& b = betas[2];
    b.setZero();
    const bool negative = x(0) < 0;
    b(0) = std::sqrt(std::abs(x(0)));
    b(1) = (negative ? x(2) < 0 : x(2) > 0) ? std::sqrt(std::abs(x(2))) : 0.0;
    if (x(1) < 0) b(0) = -b(0);
    b(2) = b(0) != 0 ? x(3) / b(0) : 0.0;
  }

  double bestError = std::numeric_limits<double>::infinity();
  for (Eigen::Vector4d& b : betas) {
    if (!b.allFinite() || b(0) == 0) continue;
    refineBetas(L, rho, b);
    if (!b.allFinite()) continue;
    Vector12d cc = Vector12d::Zero();
    for (std::size_t k = 0; k < 4; ++k) cc += b(static_cast<Eigen::Index>(k)) * v[k];
    Vector3dList pc(n);
    for (std::size_t i = 0; i < n; ++i) {
      pc[i].setZero();
      for (int j = 0; j < 4; ++j) pc[i] += alphas[i](j) * cc.segment<3>(3 * j);
    }
    // The null space fixes the points up to sign: they must lie in front of the camera.
    if (pc[0].z() < 0)
      for (auto& p : pc) p = -p;
    const SE3d candidate = alignRigid(world, pc);
    const double error = reprojectionError(world, pixels, K, candidate);
    if (std::isfinite(error) && error < bestError) {
      bestError = error;
      Tcw = candidate;
    }
  }
  return std::isfinite(bestError);
}

namespace {

int countInliers(const Vector3dList& world, const Vector2dList& pixels, const std::vector<float>& sigma2,
                 const PinholeCamera<double>& K, const SE3d& Tcw, double chi2, std::vector<char>& inlier) {
  inlier.assign(world.size(), 0);
  int count = 0;
  for (std::size_t i = 0; i < world.size(); ++i) {
    const Eigen::Vector3d pc = Tcw * world[i];
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = K.project(pc);
    const double du = uv.x() - pixels[i].x();
    const double dv = uv.y() - pixels[i].y();
    if (du * du + dv * dv < chi2 * sigma2[i]) {
      inlier[i] = 1;
      ++count;
    }
  }
  return count;
}

}  // namespace

PnpRansacResult solvePnpRansac(const Vector3dList& world, const Vector2dList& pixels,
                               const std::vector<float>& sigma2, const PinholeCamera<double>& K,
                               const PnpRansacParams& params, std::mt19937_64& rng) {
  PnpRansacResult result;
  const std::size_t n = world.size();
  if (n < 5 || static_cast<int>(n) < params.minInliers) return result;
  double iterationBound = params.maxIterations;
  // Five points, not EPnP's minimal four: with five the exact pose lies in the first two null
  // vectors and the N = 2 approximation finds it; four-point EPnP often settles elsewhere.
  constexpr std::size_t kSample = 5;
  Vector3dList sampleWorld(kSample);
  Vector2dList samplePixels(kSample);
  std::vector<char> inlier;
  for (int iteration = 0; iteration < params.maxIterations && iteration < iterationBound; ++iteration) {
    // Four distinct indices; plain modulo keeps the draw identical on every standard library.
    std::array<std::size_t, kSample> idx{};
    for (std::size_t k = 0; k < kSample; ++k) {
      bool fresh = false;
      while (!fresh) {
        idx[k] = static_cast<std::size_t>(rng() % n);
        fresh = std::find(idx.begin(), idx.begin() + static_cast<long>(k), idx[k]) == idx.begin() + static_cast<long>(k);
      }
      sampleWorld[k] = world[idx[k]];
      samplePixels[k] = pixels[idx[k]];
    }
    SE3d Tcw;
    if (!solveEpnp(sampleWorld, samplePixels, K, Tcw)) continue;
    const int count = countInliers(world, pixels, sigma2, K, Tcw, params.chi2, inlier);
    if (count > result.inliers) {
      result.inliers = count;
      result.Tcw = Tcw;
      result.inlier = inlier;
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double miss = 1 - std::pow(w, static_cast<double>(kSample));
      if (miss <= 0) break;
      iterationBound = std::log(1 - params.probability) / std::log(miss);
    }
  }
  if (result.inliers < params.minInliers) return result;

  // Refine on every inlier; keep the refinement only when it explains at least as much.
  Vector3dList inWorld;
  Vector2dList inPixels;
  for (std::size_t i = 0; i < n; ++i)
    if (result.inlier[i]) {
      inWorld.push_back(world[i]);
      inPixels.push_back(pixels[i]);
    }
  SE3d refined;
  if (solveEpnp(inWorld, inPixels, K, refined)) {
    const int count = countInliers(world, pixels, sigma2, K, refined, params.chi2, inlier);
    if (count >= result.inliers) {
      result.inliers = count;
      result.Tcw = refined;
      result.inlier = inlier;
    }
  }
  result.found = result.inliers >= params.minInliers;
  return result;
}

}  // namespace orbis
