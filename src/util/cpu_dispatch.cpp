// The library's CPU checks (see cpu_dispatch.hpp).
#include "cpu_dispatch.hpp"

namespace orbis::detail {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
bool cpuHasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}

bool cpuHasAvx512f() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}

bool cpuHasAvx512bw() {
  static const bool has = cpuHasAvx512f() && __builtin_cpu_supports("avx512bw");
  return has;
}
#else
bool cpuHasAvx2() { return false; }
bool cpuHasAvx512f() { return false; }
bool cpuHasAvx512bw() { return false; }
#endif

}  // namespace orbis::detail
