// Motion-only BA's pinhole residuals four at a time: compiled with -mavx2 (never -mfma: a fused
// multiply-add would round differently from the scalar code) and called only when the CPU has
// AVX2 (pinhole_pose_kernel.cpp checks). Contract in orbis/optim/pinhole_pose_kernel.hpp; every
// expression below is the scalar code's, named after it, in its order.
#include "orbis/optim/pinhole_pose_kernel.hpp"

#if defined(ORBIS_HAVE_AVX2_KERNELS)
#include <immintrin.h>

namespace orbis::optim::detail {
namespace {

using V = __m256d;
inline V add(V a, V b) { return _mm256_add_pd(a, b); }
inline V sub(V a, V b) { return _mm256_sub_pd(a, b); }
inline V mul(V a, V b) { return _mm256_mul_pd(a, b); }
inline V splat(double a) { return _mm256_set1_pd(a); }
inline V negate(V a) { return _mm256_xor_pd(a, splat(-0.0)); }

// Four residuals before whitening: pc = R·p + t (Eigen's quaternion rotation), r = π(pc) − z.
struct Evaluated {
  V pcx, pcy, pcz, invZ, r0, r1;
};

inline Evaluated evaluate(const PinholePose& pose, const PinholeResiduals& in, std::size_t i) {
  const V px = _mm256_loadu_pd(&in.x[i]), py = _mm256_loadu_pd(&in.y[i]), pz = _mm256_loadu_pd(&in.z[i]);
  const V qx = splat(pose.q[0]), qy = splat(pose.q[1]), qz = splat(pose.q[2]), qw = splat(pose.q[3]);
  // uv = q.vec() × p; uv += uv; R·p = p + w·uv + q.vec() × uv
  V uv0 = sub(mul(qy, pz), mul(qz, py));
  V uv1 = sub(mul(qz, px), mul(qx, pz));
  V uv2 = sub(mul(qx, py), mul(qy, px));
  uv0 = add(uv0, uv0);
  uv1 = add(uv1, uv1);
  uv2 = add(uv2, uv2);
  const V c0 = sub(mul(qy, uv2), mul(qz, uv1));
  const V c1 = sub(mul(qz, uv0), mul(qx, uv2));
  const V c2 = sub(mul(qx, uv1), mul(qy, uv0));
  Evaluated e;
  e.pcx = add(add(add(px, mul(qw, uv0)), c0), splat(pose.t[0]));
  e.pcy = add(add(add(py, mul(qw, uv1)), c1), splat(pose.t[1]));
  e.pcz = add(add(add(pz, mul(qw, uv2)), c2), splat(pose.t[2]));
  // PinholeCamera::project: invZ = 1/z; (fx·x·invZ + cx, fy·y·invZ + cy)
  e.invZ = _mm256_div_pd(splat(1.0), e.pcz);
  const V u = add(mul(mul(splat(pose.fx), e.pcx), e.invZ), splat(pose.cx));
  const V v = add(mul(mul(splat(pose.fy), e.pcy), e.invZ), splat(pose.cy));
  e.r0 = sub(u, _mm256_loadu_pd(&in.u[i]));
  e.r1 = sub(v, _mm256_loadu_pd(&in.v[i]));
  return e;
}

// s = information·‖r‖² and the kernel's ρ and ρ′ (HuberKernel or TrivialKernel::evaluate).
inline void kernel(const Evaluated& e, V information, V delta2, bool huber, V& s, V& rho, V& rho1) {
  s = mul(information, add(mul(e.r0, e.r0), mul(e.r1, e.r1)));
  if (!huber) {
    rho = s;
    rho1 = splat(1.0);
    return;
  }
  const V inside = _mm256_cmp_pd(s, delta2, _CMP_LE_OQ);
  const V root = _mm256_sqrt_pd(s), delta = _mm256_sqrt_pd(delta2);
  const V rhoOutside = sub(mul(mul(splat(2.0), delta), root), delta2);
  const V rho1Outside = _mm256_div_pd(delta, root);
  rho = _mm256_blendv_pd(rhoOutside, s, inside);
  rho1 = _mm256_blendv_pd(rho1Outside, splat(1.0), inside);
}

}  // namespace

std::size_t costPinholeBlocks(const PinholePose& pose, const PinholeResiduals& in, bool huber, double& cost) {
  const std::size_t n = in.size() / 4 * 4;
  alignas(32) double half[4];
  for (std::size_t i = 0; i < n; i += 4) {
    const Evaluated e = evaluate(pose, in, i);
    V s, rho, rho1;
    kernel(e, _mm256_loadu_pd(&in.information[i]), _mm256_loadu_pd(&in.delta2[i]), huber, s, rho, rho1);
    _mm256_store_pd(half, mul(splat(0.5), rho));
    for (double h : half) cost += h;
  }
  return n;
}

std::size_t linearizePinholeBlocks(const PinholePose& pose, const PinholeResiduals& in, bool huber, double& cost,
                                   double* hessian, double* gradient) {
  const std::size_t n = in.size() / 4 * 4;
  alignas(32) double half[4], gram[21][4], grad[6][4];
  const V fx = splat(pose.fx), fy = splat(pose.fy), zero = splat(0.0);
  for (std::size_t i = 0; i < n; i += 4) {
    const Evaluated e = evaluate(pose, in, i);
    const V information = _mm256_loadu_pd(&in.information[i]);
    V s, rho, rho1;
    kernel(e, information, _mm256_loadu_pd(&in.delta2[i]), huber, s, rho, rho1);
    _mm256_store_pd(half, mul(splat(0.5), rho));
    for (double h : half) cost += h;
    // PinholeCamera::projectJacobian, then Reprojection's [dπ, −dπ·[pc]×], row by row.
    const V invZ2 = mul(e.invZ, e.invZ);
    V j[2][6];
    j[0][0] = mul(fx, e.invZ);
    j[0][1] = zero;
    j[0][2] = mul(mul(negate(fx), e.pcx), invZ2);
    j[1][0] = zero;
    j[1][1] = mul(fy, e.invZ);
    j[1][2] = mul(mul(negate(fy), e.pcy), invZ2);
    // [pc]× = [[0, −z, y], [z, 0, −x], [−y, x, 0]]; entry (r, 3 + c) = (−d_r0·h_0c + −d_r1·h_1c) + −d_r2·h_2c
    const V hat[3][3] = {{zero, negate(e.pcz), e.pcy}, {e.pcz, zero, negate(e.pcx)}, {negate(e.pcy), e.pcx, zero}};
    for (int r = 0; r < 2; ++r) {
      const V d0 = negate(j[r][0]), d1 = negate(j[r][1]), d2 = negate(j[r][2]);
      for (int c = 0; c < 3; ++c) j[r][3 + c] = add(add(mul(d0, hat[0][c]), mul(d1, hat[1][c])), mul(d2, hat[2][c]));
    }
    // whitenAndCorrect (ρ″ ≤ 0 for both kernels: no curvature correction): r·√info, J·√info·√ρ′, r·√ρ′.
    const V sqrtInfo = _mm256_sqrt_pd(information), sqrtRho1 = _mm256_sqrt_pd(rho1);
    const V r0 = mul(mul(e.r0, sqrtInfo), sqrtRho1), r1 = mul(mul(e.r1, sqrtInfo), sqrtRho1);
    for (auto& row : j)
      for (V& entry : row) entry = mul(mul(entry, sqrtInfo), sqrtRho1);
    // Upper JᵀJ (PoseOnlyProblem::addUpperGramian) and Jᵀr, then added lane after lane.
    for (int c = 0, k = 0; c < 6; ++c)
      for (int r = 0; r <= c; ++r, ++k) _mm256_store_pd(gram[k], add(mul(j[0][r], j[0][c]), mul(j[1][r], j[1][c])));
    for (int c = 0; c < 6; ++c) _mm256_store_pd(grad[c], add(mul(j[0][c], r0), mul(j[1][c], r1)));
    for (int lane = 0; lane < 4; ++lane) {
      for (int c = 0, k = 0; c < 6; ++c)
        for (int r = 0; r <= c; ++r, ++k) hessian[c * 6 + r] += gram[k][lane];
      for (int c = 0; c < 6; ++c) gradient[c] -= grad[c][lane];
    }
  }
  return n;
}

}  // namespace orbis::optim::detail
#endif
