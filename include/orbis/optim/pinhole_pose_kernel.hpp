// orbis/optim/pinhole_pose_kernel.hpp — motion-only BA's pinhole reprojection residuals eight
// (AVX-512F) or four (AVX2) at a time, with the bits of the one-at-a-time code.
//
// Contract: PinholeResiduals holds the active MonoReprojection residuals of one pose (structure of
// arrays, in record order). linearizePinholeBlocks() evaluates residuals [0, L⌊n/L⌋) at `pose` (L lanes:
// 8 or 4, the widest this CPU runs, or the `lanes` asked for) and,
// residual after residual in that order, adds ½ρ to `cost`, the whitened JᵀJ to the upper triangle
// of `hessian` (6 × 6, column-major) and −Jᵀr to `gradient`, exactly as PoseOnlyProblem::linearize
// does with Reprojection<PinholeCamera<double>> and HuberKernel (huber) or TrivialKernel; it
// returns how many it took (the caller does the rest one at a time). costPinholeBlocks() does the
// same for the cost alone. Each lane performs the scalar code's operations in its order (no fused
// multiply-add), and the sums take the lanes one after another, so every bit is the scalar
// code's (tests/optim/slam_ba_test.cpp compares with the general problem). Available only where
// pinholePoseKernelAvailable() (an AVX2 or AVX-512 build on such a CPU); elsewhere both take
// nothing.
#pragma once

#include <cstddef>
#include <vector>

namespace orbis::optim::detail {

// A pose and the pinhole camera: quaternion (x, y, z, w), translation, intrinsics.
struct PinholePose {
  double q[4];
  double t[3];
  double fx, fy, cx, cy;
};

// Active residuals: world point, measured pixel, 1/σ², kernel threshold δ², and the record.
struct PinholeResiduals {
  std::vector<double> x, y, z, u, v, information, delta2;
  std::vector<int> record;  // index in the term's records
  // Empties the arrays.
  void clear() {
    for (auto* a : {&x, &y, &z, &u, &v, &information, &delta2}) a->clear();
    record.clear();
  }
  // Appends one residual.
  void push(const double* point, const double* pixel, double info, double d2, int index) {
    x.push_back(point[0]);
    y.push_back(point[1]);
    z.push_back(point[2]);
    u.push_back(pixel[0]);
    v.push_back(pixel[1]);
    information.push_back(info);
    delta2.push_back(d2);
    record.push_back(index);
  }
  // Number of residuals.
  std::size_t size() const { return record.size(); }
};

// Whether the code with `lanes` lanes (4 or 8; 0: any) is built and this CPU runs it.
bool pinholePoseKernelAvailable(int lanes = 0);

// See the contract; `hessian` and `gradient` are updated in place. `lanes` 0: the widest code
// available; 4 or 8: that code (tests), nothing taken if it is not available.
std::size_t linearizePinholeBlocks(const PinholePose& pose, const PinholeResiduals& residuals, bool huber,
                                   double& cost, double* hessian, double* gradient, int lanes = 0);
// See the contract.
std::size_t costPinholeBlocks(const PinholePose& pose, const PinholeResiduals& residuals, bool huber, double& cost,
                              int lanes = 0);

}  // namespace orbis::optim::detail
