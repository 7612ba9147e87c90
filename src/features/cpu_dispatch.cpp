// The module's AVX2 check (see cpu_dispatch.hpp).
#include "cpu_dispatch.hpp"

namespace orbis::detail {

bool cpuHasAvx2() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

bool cpuHasAvx512bw() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  static const bool has = __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512f");
  return has;
#else
  return false;
#endif
}

}  // namespace orbis::detail
