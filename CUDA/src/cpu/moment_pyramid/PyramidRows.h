// The inner loops of the moment pyramid's blur (PyramidBuild.cxx), written once as plain
// templates and compiled twice: for the baseline instruction set and, on x86 with GCC or
// Clang, for AVX2 + FMA, chosen at run time (the blur is multiply-adds, which FMA fuses).
//
// How: each loop is the always-inlined static run() of a small struct, which runRows
// (CpuDispatch.h) compiles for both targets.
// Both accumulate in double.
#pragma once

#include "BlurTaps.h"
#include "cpu/simd/CpuDispatch.h"

#include <cstdint>

namespace vao
{
namespace detail
{
namespace pyramid
{

constexpr int kTaps = blur::kTaps;
constexpr int kHalf = blur::kHalf;
using blur::tapSum;

/// d[k] = rows[k][i] - shift for the five taps.
template <class T>
VAO_ALWAYS_INLINE void shiftedTaps(const T* const* rows, std::int64_t i, double shift, double* d)
{
  for (int k = 0; k < kTaps; ++k)
    d[k] = static_cast<double>(rows[k][i]) - shift;
}

/// z pass from the raw volume: a[x] = sum_k w_k d_k, b[x] = sum_k w_k d_k^2 with
/// d_k = r_k[x * stride] - shift (Unit: stride 1).
template <class T, bool Unit>
struct RawRows
{
  static VAO_ALWAYS_INLINE void run(const T* const* r, const double* w, double shift,
    std::int64_t stride, std::int64_t nx, double* __restrict a, double* __restrict b)
  {
    for (std::int64_t x = 0; x < nx; ++x)
    {
      double d[kTaps];
      shiftedTaps(r, Unit ? x : x * stride, shift, d);
      a[x] = tapSum(w, d);
      b[x] = blur::squareSum(w, d);
    }
  }
};

/// z pass from a stored level: d_k = mean_k - shift, s_k = var_k + d_k^2.
struct LevelRows
{
  static VAO_ALWAYS_INLINE void run(const float* const* m, const float* const* v, const double* w,
    double shift, std::int64_t nx, double* __restrict a, double* __restrict b)
  {
    for (std::int64_t x = 0; x < nx; ++x)
    {
      double d[kTaps], s[kTaps];
      shiftedTaps(m, x, shift, d);
      for (int k = 0; k < kTaps; ++k)
        s[k] = static_cast<double>(v[k][x]) + d[k] * d[k];
      a[x] = tapSum(w, d);
      b[x] = tapSum(w, s);
    }
  }
};

/// y pass: out[x] = sum_k w_k in_k[x] for both moments.
struct ColumnRows
{
  static VAO_ALWAYS_INLINE void run(const double* const* ia, const double* const* ib,
    const double* w, std::int64_t nx, double* __restrict oa, double* __restrict ob)
  {
    for (std::int64_t x = 0; x < nx; ++x)
    {
      double ta[kTaps], tb[kTaps];
      shiftedTaps(ia, x, 0.0, ta);
      shiftedTaps(ib, x, 0.0, tb);
      oa[x] = tapSum(w, ta);
      ob[x] = tapSum(w, tb);
    }
  }
};

/// Consecutive rows in one call: the z pass of `rows` rows (row j of every tap
/// inRowStride values after row 0, its outputs outRowStride after) or the y pass of
/// output rows [y0, y1). A tile's block has rows of a dozen voxels, whose calls one by
/// one cost more than their arithmetic; each row still takes its own row loop above, so
/// the numbers are those of the whole level's rows.
template <class T, bool Unit>
struct RawPlane
{
  static VAO_ALWAYS_INLINE void run(const T* const* r, const double* w, double shift,
    std::int64_t stride, std::int64_t nx, std::int64_t rows, std::int64_t inRowStride,
    std::int64_t outRowStride, double* a, double* b)
  {
    for (std::int64_t j = 0; j < rows; ++j)
    {
      const T* row[kTaps];
      for (int k = 0; k < kTaps; ++k)
        row[k] = r[k] + j * inRowStride;
      RawRows<T, Unit>::run(row, w, shift, stride, nx, a + j * outRowStride, b + j * outRowStride);
    }
  }
};

struct LevelPlane
{
  static VAO_ALWAYS_INLINE void run(const float* const* m, const float* const* v, const double* w,
    double shift, std::int64_t nx, std::int64_t rows, std::int64_t inRowStride,
    std::int64_t outRowStride, double* a, double* b)
  {
    for (std::int64_t j = 0; j < rows; ++j)
    {
      const float* means[kTaps];
      const float* variances[kTaps];
      for (int k = 0; k < kTaps; ++k)
      {
        means[k] = m[k] + j * inRowStride;
        variances[k] = v[k] + j * inRowStride;
      }
      LevelRows::run(means, variances, w, shift, nx, a + j * outRowStride, b + j * outRowStride);
    }
  }
};

/// The y pass of output rows [y0, y1) from z-blurred input rows [ya, ...) kept rowStride
/// apart: output row yo takes input rows yo * step + k - kHalf clamped to [0, ny) with
/// the weights w + yo * kTaps (no library min/max: this is compiled for AVX2).
struct ColumnPlane
{
  static VAO_ALWAYS_INLINE void run(const double* za, const double* zb, std::int64_t rowStride,
    std::int64_t ya, std::int64_t ny, std::int64_t step, const double* w, std::int64_t y0,
    std::int64_t y1, std::int64_t nx, double* oa, double* ob, std::int64_t outRowStride)
  {
    for (std::int64_t yo = y0; yo < y1; ++yo)
    {
      const double* ia[kTaps];
      const double* ib[kTaps];
      for (int k = 0; k < kTaps; ++k)
      {
        std::int64_t y = yo * step + k - kHalf;
        y = y < 0 ? 0 : y > ny - 1 ? ny - 1 : y;
        ia[k] = za + (y - ya) * rowStride;
        ib[k] = zb + (y - ya) * rowStride;
      }
      ColumnRows::run(
        ia, ib, w + yo * kTaps, nx, oa + (yo - y0) * outRowStride, ob + (yo - y0) * outRowStride);
    }
  }
};

/// x pass over unclipped outputs [begin, end): pa[xo * Step + k] is tap k of output xo;
/// stores mean = A + shift and variance = max(0, B - A^2) as float at mean[xo - begin].
template <int Step>
struct InteriorRow
{
  static VAO_ALWAYS_INLINE void run(const double* pa, const double* pb, const double* w,
    double shift, std::int64_t begin, std::int64_t end, float* __restrict mean,
    float* __restrict variance)
  {
    for (std::int64_t xo = begin; xo < end; ++xo)
    {
      blur::levelMoments(tapSum(w, pa + Step * xo), tapSum(w, pb + Step * xo), shift,
        mean[xo - begin], variance[xo - begin]);
    }
  }
};

} // namespace pyramid
} // namespace detail
} // namespace vao
