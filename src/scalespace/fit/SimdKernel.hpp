#pragma once
// Which implementation of a hot loop runs. The project builds for baseline x86-64 (SSE2: 2-wide,
// no FMA; -march=native for the whole build was measured no faster overall), so the few loops
// that gain from wider instructions (fit/DerivativeSums, fit/RobustReweighting) have an AVX2 + FMA
// version compiled on its own (__attribute__((target))) and chosen at run time, next to a
// portable one that tests can ask for on any CPU. A machine always takes the same path, so results
// do not depend on the thread count; the two paths differ in the last bits (FMA rounds once).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SCALESPACE_HAVE_AVX2_TARGET 1
#endif

namespace scalespace {

enum class SimdKernel {
  Auto,      // the fastest one this CPU runs (what the fits use)
  Portable,  // plain C++ (any CPU)
  Avx2Fma    // 4-wide fused multiply-adds (x86-64 with AVX2 and FMA)
};

/// True when the CPU (and the compiler) can run SimdKernel::Avx2Fma.
bool avx2FmaAvailable();

/// Whether a loop asked for `kernel` runs its AVX2 + FMA version: Auto and Avx2Fma where it is
/// available (Avx2Fma elsewhere runs the portable one), never for Portable.
inline bool useAvx2Fma(SimdKernel kernel) {
  return kernel != SimdKernel::Portable && avx2FmaAvailable();
}

}  // namespace scalespace
