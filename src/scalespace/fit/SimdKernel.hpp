#pragma once
// Which implementation of a hot loop runs. The project builds for baseline x86-64 (SSE2: 2-wide,
// no FMA; -march=native for the whole build gave no overall gain), so the few loops that gain
// from wider instructions (fit/DerivativeSums, fit/RobustReweighting) have an AVX2 + FMA version
// (and the re-weighting an AVX-512 one) compiled on its own (__attribute__((target))) and chosen
// at run time, next to a portable one that tests can ask for on any CPU. A machine always
// takes the same path, so results do not depend on the thread count; the two paths differ in the
// last bits (FMA rounds once).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SCALESPACE_HAVE_AVX2_TARGET 1
// The instruction sets a function of each path is compiled for: what avx2FmaAvailable() and
// avx512Available() check at run time.
#define SCALESPACE_TARGET_AVX2 __attribute__((target("avx2,fma")))
#define SCALESPACE_TARGET_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,fma")))
#endif

namespace scalespace {

enum class SimdKernel {
  Auto,      // the fastest one this CPU runs (what the fits use)
  Portable,  // plain C++ (any CPU)
  Avx2Fma,   // 4-wide fused multiply-adds (x86-64 with AVX2 and FMA)
  Avx512     // 8-wide with mask registers (x86-64 with AVX-512 F, DQ and VL)
};

/// True when the CPU (and the compiler) can run SimdKernel::Avx2Fma.
bool avx2FmaAvailable();
/// True when the CPU (and the compiler) can run SimdKernel::Avx512.
bool avx512Available();

/// Whether a loop that has an AVX-512 version runs it: Auto and Avx512 where it is available.
inline bool useAvx512(SimdKernel kernel) {
  return (kernel == SimdKernel::Auto || kernel == SimdKernel::Avx512) && avx512Available();
}

/// Whether a loop asked for `kernel` runs its AVX2 + FMA version: Auto, Avx2Fma and Avx512 where
/// it is available (elsewhere the portable one runs), never for Portable. A loop with an AVX-512
/// version asks useAvx512 first.
inline bool useAvx2Fma(SimdKernel kernel) {
  return kernel != SimdKernel::Portable && avx2FmaAvailable();
}

}  // namespace scalespace
