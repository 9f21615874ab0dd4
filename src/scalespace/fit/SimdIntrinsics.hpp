#pragma once
// The x86 intrinsics of the AVX2 and AVX-512 kernels (fit/SimdKernel.hpp). Included only by the
// .cpp files that define such kernels, never by a header: the warnings silenced below stay
// silenced for the rest of the including file.
#include "scalespace/fit/SimdKernel.hpp"

#ifdef SCALESPACE_HAVE_AVX2_TARGET
// GCC 12's AVX-512 intrinsics fill unused operands with a self-initialised _mm512_undefined_pd(),
// which -Wuninitialized reports at every inlined use (GCC bug 105593). The warning points into
// the intrinsics header, not at a use of ours.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#endif

// Put before a loop that zeroes an array of accumulator registers: unrolled, it becomes a few
// register clears, where GCC otherwise turns the loop into a memset of the array in memory (a
// `rep stos`, which showed in the robust pass's profile).
#if defined(__GNUC__) && !defined(__clang__)
#define SCALESPACE_UNROLLED_ZERO _Pragma("GCC unroll 16")
#else
#define SCALESPACE_UNROLLED_ZERO
#endif
