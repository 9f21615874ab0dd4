#include "scalespace/fit/SimdKernel.hpp"

namespace scalespace {

bool avx2FmaAvailable() {
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

bool avx512Available() {
#ifdef SCALESPACE_HAVE_AVX2_TARGET
  static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                          __builtin_cpu_supports("avx512vl");
  return has;
#else
  return false;
#endif
}

}  // namespace scalespace
