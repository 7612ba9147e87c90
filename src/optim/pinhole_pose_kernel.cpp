// The run-time choice of motion-only BA's vector pinhole code (contract in
// orbis/optim/pinhole_pose_kernel.hpp): eight lanes (AVX-512F) or four (AVX2) where built and
// run by this CPU; otherwise the entry points take nothing.
#include "orbis/optim/pinhole_pose_kernel.hpp"

#include "../util/cpu_dispatch.hpp"

namespace orbis::optim::detail {

// The units' entry points (pinhole_pose_kernel_avx2.cpp, pinhole_pose_kernel_avx512.cpp).
std::size_t linearizePinholeBlocksAvx2(const PinholePose&, const PinholeResiduals&, bool, double&, double*, double*);
std::size_t costPinholeBlocksAvx2(const PinholePose&, const PinholeResiduals&, bool, double&);
std::size_t linearizePinholeBlocksAvx512(const PinholePose&, const PinholeResiduals&, bool, double&, double*, double*);
std::size_t costPinholeBlocksAvx512(const PinholePose&, const PinholeResiduals&, bool, double&);

namespace {

// Whether the four- and eight-lane units are built and this CPU runs them.
bool fourLanes() {
#if defined(ORBIS_HAVE_AVX2_KERNELS)
  return ::orbis::detail::cpuHasAvx2();
#else
  return false;
#endif
}

bool eightLanes() {
#if defined(ORBIS_HAVE_AVX512_KERNELS)
  return ::orbis::detail::cpuHasAvx512f();
#else
  return false;
#endif
}

// The lanes a call runs with: `lanes` if available, the widest available for 0, else none.
int resolveLanes(int lanes) {
  if (lanes == 0) return eightLanes() ? 8 : fourLanes() ? 4 : 0;
  return pinholePoseKernelAvailable(lanes) ? lanes : 0;
}

}  // namespace

bool pinholePoseKernelAvailable(int lanes) {
  switch (lanes) {
    case 0: return eightLanes() || fourLanes();
    case 4: return fourLanes();
    case 8: return eightLanes();
    default: return false;
  }
}

std::size_t linearizePinholeBlocks(const PinholePose& pose, const PinholeResiduals& residuals, bool huber,
                                   double& cost, double* hessian, double* gradient, int lanes) {
  switch (resolveLanes(lanes)) {
#if defined(ORBIS_HAVE_AVX512_KERNELS)
    case 8: return linearizePinholeBlocksAvx512(pose, residuals, huber, cost, hessian, gradient);
#endif
#if defined(ORBIS_HAVE_AVX2_KERNELS)
    case 4: return linearizePinholeBlocksAvx2(pose, residuals, huber, cost, hessian, gradient);
#endif
    default: return 0;
  }
}

std::size_t costPinholeBlocks(const PinholePose& pose, const PinholeResiduals& residuals, bool huber, double& cost,
                              int lanes) {
  switch (resolveLanes(lanes)) {
#if defined(ORBIS_HAVE_AVX512_KERNELS)
    case 8: return costPinholeBlocksAvx512(pose, residuals, huber, cost);
#endif
#if defined(ORBIS_HAVE_AVX2_KERNELS)
    case 4: return costPinholeBlocksAvx2(pose, residuals, huber, cost);
#endif
    default: return 0;
  }
}

}  // namespace orbis::optim::detail
