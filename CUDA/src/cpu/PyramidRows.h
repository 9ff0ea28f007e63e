// The inner loops of the moment pyramid's blur (PyramidBuild.cxx), written once as plain
// templates and compiled twice: for the baseline instruction set and, on x86 with GCC or
// Clang, for AVX2 + FMA, chosen at run time (about 30% faster on the build machine).
//
// How: each loop is the always-inlined static run() of a small struct; runRows<Kernel>
// instantiates it inside a function with the baseline target and inside one with
// target("avx2,fma"), where the inlined loop is vectorised for that target. Only those
// leaf functions carry the target, so no inline function of the standard library is ever
// compiled for AVX2 (which could reach a machine without it through the linker).
// Both accumulate in double.
#pragma once

#include <cstdint>

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

namespace vao
{
namespace detail
{
namespace pyramid
{

constexpr int kTaps = 5;
constexpr int kHalf = 2;

/// z pass from the raw volume: a[x] = sum_k w_k d_k, b[x] = sum_k w_k d_k^2 with
/// d_k = r_k[x * stride] - shift (Unit: stride 1).
template <class T, bool Unit>
struct RawRows
{
  static VAO_ALWAYS_INLINE void run(const T* const* r, const double* w, double shift, std::int64_t stride,
    std::int64_t nx, double* __restrict a, double* __restrict b)
  {
    const T *r0 = r[0], *r1 = r[1], *r2 = r[2], *r3 = r[3], *r4 = r[4];
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];
    for (std::int64_t x = 0; x < nx; ++x)
    {
      const std::int64_t i = Unit ? x : x * stride;
      const double d0 = static_cast<double>(r0[i]) - shift;
      const double d1 = static_cast<double>(r1[i]) - shift;
      const double d2 = static_cast<double>(r2[i]) - shift;
      const double d3 = static_cast<double>(r3[i]) - shift;
      const double d4 = static_cast<double>(r4[i]) - shift;
      a[x] = w0 * d0 + w1 * d1 + w2 * d2 + w3 * d3 + w4 * d4;
      b[x] = w0 * d0 * d0 + w1 * d1 * d1 + w2 * d2 * d2 + w3 * d3 * d3 + w4 * d4 * d4;
    }
  }
};

/// z pass from a stored level: d_k = mean_k - shift, s_k = var_k + d_k^2.
struct LevelRows
{
  static VAO_ALWAYS_INLINE void run(const float* const* m, const float* const* v, const double* w,
    double shift, std::int64_t nx, double* __restrict a, double* __restrict b)
  {
    const float *m0 = m[0], *m1 = m[1], *m2 = m[2], *m3 = m[3], *m4 = m[4];
    const float *v0 = v[0], *v1 = v[1], *v2 = v[2], *v3 = v[3], *v4 = v[4];
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];
    for (std::int64_t x = 0; x < nx; ++x)
    {
      const double d0 = static_cast<double>(m0[x]) - shift;
      const double d1 = static_cast<double>(m1[x]) - shift;
      const double d2 = static_cast<double>(m2[x]) - shift;
      const double d3 = static_cast<double>(m3[x]) - shift;
      const double d4 = static_cast<double>(m4[x]) - shift;
      a[x] = w0 * d0 + w1 * d1 + w2 * d2 + w3 * d3 + w4 * d4;
      b[x] = w0 * (static_cast<double>(v0[x]) + d0 * d0) + w1 * (static_cast<double>(v1[x]) + d1 * d1) +
        w2 * (static_cast<double>(v2[x]) + d2 * d2) + w3 * (static_cast<double>(v3[x]) + d3 * d3) +
        w4 * (static_cast<double>(v4[x]) + d4 * d4);
    }
  }
};

/// y pass: out[x] = sum_k w_k in_k[x] for both moments.
struct ColumnRows
{
  static VAO_ALWAYS_INLINE void run(const double* const* ia, const double* const* ib, const double* w,
    std::int64_t nx, double* __restrict oa, double* __restrict ob)
  {
    const double *a0 = ia[0], *a1 = ia[1], *a2 = ia[2], *a3 = ia[3], *a4 = ia[4];
    const double *b0 = ib[0], *b1 = ib[1], *b2 = ib[2], *b3 = ib[3], *b4 = ib[4];
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];
    for (std::int64_t x = 0; x < nx; ++x)
    {
      oa[x] = w0 * a0[x] + w1 * a1[x] + w2 * a2[x] + w3 * a3[x] + w4 * a4[x];
      ob[x] = w0 * b0[x] + w1 * b1[x] + w2 * b2[x] + w3 * b3[x] + w4 * b4[x];
    }
  }
};

/// x pass over unclipped outputs [begin, end): pa[xo * Step + k] is tap k of output xo;
/// stores mean = A + shift and variance = max(0, B - A^2) as float.
template <int Step>
struct InteriorRow
{
  static VAO_ALWAYS_INLINE void run(const double* pa, const double* pb, const double* w, double shift,
    std::int64_t begin, std::int64_t end, float* __restrict mean, float* __restrict variance)
  {
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];
    for (std::int64_t xo = begin; xo < end; ++xo)
    {
      const std::int64_t i = Step * xo;
      const double sa = w0 * pa[i] + w1 * pa[i + 1] + w2 * pa[i + 2] + w3 * pa[i + 3] + w4 * pa[i + 4];
      const double sb = w0 * pb[i] + w1 * pb[i + 1] + w2 * pb[i + 2] + w3 * pb[i + 3] + w4 * pb[i + 4];
      mean[xo] = static_cast<float>(sa + shift);
      const double var = sb - sa * sa;
      variance[xo] = static_cast<float>(var > 0.0 ? var : 0.0);
    }
  }
};

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

} // namespace pyramid
} // namespace detail
} // namespace vao
