#include "evio/core/cpu_features.h"

namespace evio {

#if defined(__GNUC__) && defined(__x86_64__)
// __builtin_cpu_init first: a caller may run during static initialisation.
bool cpuHasAvx() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx") != 0;
  }();
  return has;
}

bool cpuHasAvx2() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
}
bool cpuHasAvx512f() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") != 0;
  }();
  return has;
}
#else
bool cpuHasAvx() { return false; }
bool cpuHasAvx2() { return false; }
bool cpuHasAvx512f() { return false; }
#endif

}  // namespace evio
