// Run-time choice between the baseline and an AVX2 + FMA build of one hot loop.
//
// How: the loop is the always-inlined static run() of a small struct; runRows<Kernel>
// instantiates it inside a function with the baseline target and inside one with
// target("avx2,fma"), where the inlined loop is vectorised for that target. Only those
// leaf functions carry the target, so no inline function of the standard library is ever
// compiled for AVX2 (which could reach a machine without it through the linker).
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
#endif

/// True when the processor runs the AVX2 + FMA versions (checked once).
inline bool cpuHasAvx2()
{
#if VAO_HAVE_AVX2_TARGET
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

/// Kernel::run(args...) in the version for this processor.
template <class Kernel, class... Args>
void runRows(bool avx2, Args... args)
{
#if VAO_HAVE_AVX2_TARGET
  if (avx2)
  {
    runAvx2<Kernel>(args...);
    return;
  }
#endif
  (void)avx2;
  runBaseline<Kernel>(args...);
}

} // namespace detail
} // namespace vao
