// The run-time choice of motion-only BA's AVX2 pinhole code (contract in
// orbis/optim/pinhole_pose_kernel.hpp); without it both entry points take nothing.
#include "orbis/optim/pinhole_pose_kernel.hpp"

namespace orbis::optim::detail {

bool pinholePoseKernelAvailable() {
#if defined(ORBIS_HAVE_AVX2_KERNELS) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

#if !defined(ORBIS_HAVE_AVX2_KERNELS)
std::size_t linearizePinholeBlocks(const PinholePose&, const PinholeResiduals&, bool, double&, double*, double*) {
  return 0;
}
std::size_t costPinholeBlocks(const PinholePose&, const PinholeResiduals&, bool, double&) { return 0; }
#endif

}  // namespace orbis::optim::detail
