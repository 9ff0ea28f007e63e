// Run-time choice between the baseline, an AVX2 + FMA and an AVX-512 build of one hot
// loop.
//
// How: the loop is the always-inlined static run() of a small struct; runRows<Kernel>
// instantiates it inside a function with the baseline target, one with target("avx2,fma")
// and one with the AVX-512 subsets of x86-64-v4, where the inlined loop is vectorised for
// that target (four or eight doubles a vector). Only those leaf functions carry the
// target, so no inline function of the standard library is ever compiled for AVX2 or
// AVX-512 (which could reach a machine without it through the linker). The loops have no
// reductions across lanes and both vector tiers contract the same multiply-adds, so AVX2
// and AVX-512 give the same numbers bit for bit; the baseline has no FMA and may differ in
// the last bit (test_simd_tiers.cxx checks both, through limitSimdTier).
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define VAO_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define VAO_ALWAYS_INLINE inline
#endif

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define VAO_HAVE_AVX2_TARGET 1
#else
#define VAO_HAVE_AVX2_TARGET 0
#endif

#if VAO_HAVE_AVX2_TARGET
// Hand-written AVX2 code (intrinsics): its entry points, called from baseline code, and
// the helpers they inline.
#define VAO_AVX2_INLINE __attribute__((target("avx2,fma"))) inline
#define VAO_AVX2_HELPER __attribute__((target("avx2,fma"), always_inline)) inline
#endif

namespace vao
{
namespace detail
{

/// The instruction sets a row loop can be built for, in order.
enum class SimdTier : int
{
  Baseline = 0,
  Avx2 = 1,   // AVX2 + FMA
  Avx512 = 2, // AVX-512 F, VL, DQ, BW (x86-64-v4)
};

/// The best tier this processor runs, lowered to the limit set by limitSimdTier.
SimdTier cpuSimdTier();

/// Caps the tier every later row loop uses (tests: each tier against the others);
/// SimdTier::Avx512 lifts the cap.
void limitSimdTier(SimdTier limit);

/// cpuSimdTier(), at most `ceiling`: loops that gain nothing from AVX-512 (or lose) stay
/// on AVX2.
inline SimdTier cpuSimdTierUpTo(SimdTier ceiling)
{
  const SimdTier tier = cpuSimdTier();
  return tier < ceiling ? tier : ceiling;
}

/// True when the processor runs the AVX2 + FMA versions (the hand-written intrinsics).
inline bool cpuHasAvx2()
{
  return cpuSimdTier() >= SimdTier::Avx2;
}

template <class Kernel, class... Args>
void runBaseline(Args... args)
{
  Kernel::run(args...);
}

#if VAO_HAVE_AVX2_TARGET
template <class Kernel, class... Args>
__attribute__((target("avx2,fma"))) void runAvx2(Args... args)
{
  Kernel::run(args...);
}

// The AVX-512 subsets of x86-64-v4, with the AVX2 and FMA below them.
#define VAO_AVX512_FEATURES "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma"

// GCC vectorises for 256 bits on AVX-512 unless told to use the full width; Clang takes
// min_vector_width for the same.
#if defined(__clang__)
#define VAO_AVX512_TARGET __attribute__((target(VAO_AVX512_FEATURES), min_vector_width(512)))
#else
#define VAO_AVX512_TARGET __attribute__((target(VAO_AVX512_FEATURES ",prefer-vector-width=512")))
#endif

// Hand-written AVX-512 code (intrinsics): its entry points and the helpers they inline.
#define VAO_AVX512_INLINE __attribute__((target(VAO_AVX512_FEATURES))) inline
#define VAO_AVX512_HELPER __attribute__((target(VAO_AVX512_FEATURES), always_inline)) inline

template <class Kernel, class... Args>
VAO_AVX512_TARGET void runAvx512(Args... args)
{
  Kernel::run(args...);
}
#endif

/// Kernel::run(args...) in the version of `tier` (from cpuSimdTier).
template <class Kernel, class... Args>
void runRows(SimdTier tier, Args... args)
{
#if VAO_HAVE_AVX2_TARGET
  if (tier == SimdTier::Avx512)
  {
    runAvx512<Kernel>(args...);
    return;
  }
  if (tier == SimdTier::Avx2)
  {
    runAvx2<Kernel>(args...);
    return;
  }
#endif
  (void)tier;
  runBaseline<Kernel>(args...);
}

/// Kernel<Bytes>::run(args...) in the version of `tier`, Bytes its vector width (16, 32 or
/// 64): for loops written with GCC's and Clang's vector types, which a target narrower than
/// the type would split through the stack.
template <template <int> class Kernel, class... Args>
void runRowsOfWidth(SimdTier tier, Args... args)
{
#if VAO_HAVE_AVX2_TARGET
  if (tier == SimdTier::Avx512)
  {
    runAvx512<Kernel<64>>(args...);
    return;
  }
  if (tier == SimdTier::Avx2)
  {
    runAvx2<Kernel<32>>(args...);
    return;
  }
#endif
  (void)tier;
  runBaseline<Kernel<16>>(args...);
}

} // namespace detail
} // namespace vao
