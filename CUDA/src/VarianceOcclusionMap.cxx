// Variance occlusion maps (Penner & Mitchell 2008; the Penner & Mitchell section of
// METHODS.md): a pyramid of blurred first and second moments, and the surface ambient
// occlusion and soft shadows sampled from it.
//
// Layout of the pyramid build. One routine, blurDecimate, turns a "source" grid into the
// next level: a separable normalised 5-tap Gaussian (sigma = 1 voxel, weights renormalised
// where the kernel is clipped by the volume) evaluated only at the kept voxels (every
// voxel, or every second one per axis). It streams: for each output slice, rows are first
// blurred along z straight from the source (5 rows in, one row out), kept in a ring of 5
// rows, blurred along y from the ring and along x into the output. The working set is a
// handful of rows, so the passes run from L1/L2 and never write a full-size temporary.
//
// Precision. The source supplies per voxel d = x - K (K: the volume's sampled mean) and
// the second moment s = var + d^2 (var = 0 for the raw volume), both in double; the blur
// accumulates in double and the level stores mean = A + K and variance = max(0, B - A^2)
// as float. The next level is built from those stored floats: blurring var + (mean-K)^2
// is the same second moment, and the cancellation B - A^2 happens in double on values
// shifted by K, so the only loss is the float rounding of the stored mean and variance
// (relative 6e-8 each), never the catastrophic E[v^2] - mu^2 of float moments.
#include "vao/VarianceOcclusionMap.h"

#include "Parallel.h"
#include "VolumeAccess.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(_WIN32)
#include <malloc.h>
#endif

namespace vao
{
namespace detail
{

void* allocateLevelStorage(std::size_t bytes)
{
  constexpr std::size_t kHugePage = std::size_t(2) << 20;
#if defined(_WIN32)
  return _aligned_malloc(bytes > 0 ? bytes : 1, bytes < kHugePage ? 64 : kHugePage);
#else
  if (bytes < kHugePage)
  {
    return std::malloc(bytes > 0 ? bytes : 1);
  }
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* block = std::aligned_alloc(kHugePage, rounded);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (block)
  {
    madvise(block, rounded, MADV_HUGEPAGE); // advisory: ignored where THP is off
  }
#endif
  return block;
#endif
}

void freeLevelStorage(void* block) noexcept
{
#if defined(_WIN32)
  _aligned_free(block);
#else
  std::free(block);
#endif
}

} // namespace detail

namespace
{

constexpr int kTaps = 5;
constexpr int kHalf = 2;

/// Normalised weights of the clipped 5-tap Gaussian for each kept output index along one
/// axis of n input voxels: weights[o * 5 + k] for input index o * step + k - 2 (0 where
/// that input is outside [0, n)).
std::vector<double> axisWeights(std::int64_t n, std::int64_t outN, int step)
{
  static const double base[kTaps] = { std::exp(-2.0), std::exp(-0.5), 1.0, std::exp(-0.5),
    std::exp(-2.0) };
  std::vector<double> weights(static_cast<std::size_t>(outN * kTaps), 0.0);
  for (std::int64_t o = 0; o < outN; ++o)
  {
    const std::int64_t centre = o * step;
    double sum = 0.0;
    for (int k = 0; k < kTaps; ++k)
    {
      const std::int64_t i = centre + k - kHalf;
      if (i >= 0 && i < n)
      {
        sum += base[k];
      }
    }
    for (int k = 0; k < kTaps; ++k)
    {
      const std::int64_t i = centre + k - kHalf;
      weights[o * kTaps + k] = (i >= 0 && i < n) ? base[k] / sum : 0.0;
    }
  }
  return weights;
}

// ---------------------------------------------------------------------------------------
// The inner loops, compiled twice: for the baseline instruction set and, on x86 with GCC
// or Clang, for AVX2 + FMA (chosen at run time; about 30% faster on the build). The FMA
// version rounds differently in the last bit; both accumulate in double.

#define VAO_VOM_DEFINE_KERNELS(SUFFIX, ATTRIBUTE)                                                \
  /* a[x] = sum_k w_k d_k, b[x] = sum_k w_k d_k^2, d_k = r_k[x * stride] - shift */           \
  template <class T, bool Unit>                                                                \
  ATTRIBUTE void zRaw##SUFFIX(const T* const* r, const double* w, double shift,                \
    std::int64_t stride, std::int64_t nx, double* __restrict a, double* __restrict b)           \
  {                                                                                            \
    const T *r0 = r[0], *r1 = r[1], *r2 = r[2], *r3 = r[3], *r4 = r[4];                        \
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];                        \
    for (std::int64_t x = 0; x < nx; ++x)                                                      \
    {                                                                                          \
      const std::int64_t i = Unit ? x : x * stride;                                            \
      const double d0 = static_cast<double>(r0[i]) - shift;                                    \
      const double d1 = static_cast<double>(r1[i]) - shift;                                    \
      const double d2 = static_cast<double>(r2[i]) - shift;                                    \
      const double d3 = static_cast<double>(r3[i]) - shift;                                    \
      const double d4 = static_cast<double>(r4[i]) - shift;                                    \
      a[x] = w0 * d0 + w1 * d1 + w2 * d2 + w3 * d3 + w4 * d4;                                  \
      b[x] = w0 * d0 * d0 + w1 * d1 * d1 + w2 * d2 * d2 + w3 * d3 * d3 + w4 * d4 * d4;         \
    }                                                                                          \
  }                                                                                            \
  /* The same from a stored level: d_k = mean_k - shift, s_k = var_k + d_k^2. */               \
  ATTRIBUTE void zLevel##SUFFIX(const float* const* m, const float* const* v, const double* w, \
    double shift, std::int64_t nx, double* __restrict a, double* __restrict b)                  \
  {                                                                                            \
    const float *m0 = m[0], *m1 = m[1], *m2 = m[2], *m3 = m[3], *m4 = m[4];                    \
    const float *v0 = v[0], *v1 = v[1], *v2 = v[2], *v3 = v[3], *v4 = v[4];                    \
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];                        \
    for (std::int64_t x = 0; x < nx; ++x)                                                      \
    {                                                                                          \
      const double d0 = static_cast<double>(m0[x]) - shift;                                    \
      const double d1 = static_cast<double>(m1[x]) - shift;                                    \
      const double d2 = static_cast<double>(m2[x]) - shift;                                    \
      const double d3 = static_cast<double>(m3[x]) - shift;                                    \
      const double d4 = static_cast<double>(m4[x]) - shift;                                    \
      a[x] = w0 * d0 + w1 * d1 + w2 * d2 + w3 * d3 + w4 * d4;                                  \
      b[x] = w0 * (static_cast<double>(v0[x]) + d0 * d0) +                                     \
        w1 * (static_cast<double>(v1[x]) + d1 * d1) + w2 * (static_cast<double>(v2[x]) + d2 * d2) + \
        w3 * (static_cast<double>(v3[x]) + d3 * d3) + w4 * (static_cast<double>(v4[x]) + d4 * d4); \
    }                                                                                          \
  }                                                                                            \
  /* y pass: out[x] = sum_k w_k in_k[x] for both moments. */                                   \
  ATTRIBUTE void yPass##SUFFIX(const double* const* ia, const double* const* ib, const double* w, \
    std::int64_t nx, double* __restrict oa, double* __restrict ob)                               \
  {                                                                                            \
    const double *a0 = ia[0], *a1 = ia[1], *a2 = ia[2], *a3 = ia[3], *a4 = ia[4];              \
    const double *b0 = ib[0], *b1 = ib[1], *b2 = ib[2], *b3 = ib[3], *b4 = ib[4];              \
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];                        \
    for (std::int64_t x = 0; x < nx; ++x)                                                      \
    {                                                                                          \
      oa[x] = w0 * a0[x] + w1 * a1[x] + w2 * a2[x] + w3 * a3[x] + w4 * a4[x];                  \
      ob[x] = w0 * b0[x] + w1 * b1[x] + w2 * b2[x] + w3 * b3[x] + w4 * b4[x];                  \
    }                                                                                          \
  }                                                                                            \
  /* x pass over unclipped outputs [begin, end): pa[xo * Step + k] is tap k of output xo. */   \
  template <int Step>                                                                          \
  ATTRIBUTE void xInterior##SUFFIX(const double* pa, const double* pb, const double* w,       \
    double shift, std::int64_t begin, std::int64_t end, float* __restrict mean,                 \
    float* __restrict variance)                                                                \
  {                                                                                            \
    const double w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3], w4 = w[4];                        \
    for (std::int64_t xo = begin; xo < end; ++xo)                                              \
    {                                                                                          \
      const std::int64_t i = Step * xo;                                                        \
      const double sa = w0 * pa[i] + w1 * pa[i + 1] + w2 * pa[i + 2] + w3 * pa[i + 3] + w4 * pa[i + 4]; \
      const double sb = w0 * pb[i] + w1 * pb[i + 1] + w2 * pb[i + 2] + w3 * pb[i + 3] + w4 * pb[i + 4]; \
      mean[xo] = static_cast<float>(sa + shift);                                               \
      const double var = sb - sa * sa;                                                         \
      variance[xo] = static_cast<float>(var > 0.0 ? var : 0.0);                                \
    }                                                                                          \
  }

VAO_VOM_DEFINE_KERNELS(Generic, )

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define VAO_VOM_HAVE_AVX2 1
VAO_VOM_DEFINE_KERNELS(Avx2, __attribute__((target("avx2,fma"))))
bool cpuHasAvx2()
{
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}
#else
#define VAO_VOM_HAVE_AVX2 0
bool cpuHasAvx2()
{
  return false;
}
#endif

#if VAO_VOM_HAVE_AVX2
#define VAO_VOM_DISPATCH(avx, NAME, ...)                                                       \
  do                                                                                           \
  {                                                                                            \
    if (avx)                                                                                   \
      NAME##Avx2 __VA_ARGS__;                                                                  \
    else                                                                                       \
      NAME##Generic __VA_ARGS__;                                                               \
  } while (false)
#else
#define VAO_VOM_DISPATCH(avx, NAME, ...) NAME##Generic __VA_ARGS__
#endif

/// Raw volume as a source: d = v - K, s = d^2.
template <class T>
struct RawSource
{
  detail::TypedVolume<T> volume;
  double shift;

  Index3 dims() const { return volume.dims; }
  /// a[x] = sum_k w[k] d(x, y, z_k), b[x] = sum_k w[k] s(x, y, z_k) over the 5 rows
  /// (y, z[k]); a clipped tap has weight 0 and a valid (clamped) row.
  void blurRows(std::int64_t y, const std::int64_t* z, const double* w, double* a, double* b,
    bool avx) const
  {
    const T* rows[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      rows[k] = volume.row(y, z[k]);
    }
    const std::int64_t nx = volume.dims[0];
    if (volume.stride == 1)
    {
      VAO_VOM_DISPATCH(avx, zRaw, <T, true>(rows, w, shift, 1, nx, a, b));
    }
    else
    {
      VAO_VOM_DISPATCH(avx, zRaw, <T, false>(rows, w, shift, volume.stride, nx, a, b));
    }
  }
};

/// A stored level as a source: d = mean - K, s = variance + d^2.
struct LevelSource
{
  const MomentLevel* level;
  double shift;

  Index3 dims() const { return level->dims; }
  void blurRows(std::int64_t y, const std::int64_t* z, const double* w, double* a, double* b,
    bool avx) const
  {
    const float* means[kTaps];
    const float* variances[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      const std::int64_t offset = (z[k] * level->dims[1] + y) * level->dims[0];
      means[k] = level->mean.data() + offset;
      variances[k] = level->variance.data() + offset;
    }
    VAO_VOM_DISPATCH(avx, zLevel, (means, variances, w, shift, level->dims[0], a, b));
  }
};

/// Blurs the source and keeps every `step`-th voxel per axis (step 1 or 2) into `out`
/// (dims, mean and variance; geometry is the caller's). Returns false when cancelled.
template <class Source>
bool blurDecimate(const Source& source, int step, double shift, MomentLevel& out,
  const Execution& execution, int threads)
{
  const Index3 n = source.dims();
  Index3 m;
  for (int a = 0; a < 3; ++a)
  {
    m[a] = step == 1 ? n[a] : (n[a] + 1) / 2;
  }
  out.dims = m;
  const std::int64_t outCount = m[0] * m[1] * m[2];
  // Every voxel is written below: a level of the same size (a rebuild) keeps its storage
  // untouched, which saves the page faults of fresh arrays.
  out.mean.resize(static_cast<std::size_t>(outCount));
  out.variance.resize(static_cast<std::size_t>(outCount));
  const std::vector<double> wx = axisWeights(n[0], m[0], step);
  const std::vector<double> wy = axisWeights(n[1], m[1], step);
  const std::vector<double> wz = axisWeights(n[2], m[2], step);

  double kernel[kTaps];
  {
    double sum = 0.0;
    for (int k = 0; k < kTaps; ++k)
    {
      kernel[k] = std::exp(-0.5 * (k - kHalf) * (k - kHalf));
      sum += kernel[k];
    }
    for (double& w : kernel)
    {
      w /= sum;
    }
  }
  detail::LoopControl control(execution, m[2]);
  const bool avx = cpuHasAvx2();
  const std::int64_t nx = n[0];
  const std::int64_t paddedX = nx + 2 * kHalf + 2 * step; // room for the x taps of every kept voxel
  auto body = [&](std::int64_t zBegin, std::int64_t zEnd, bool onCallingThread) {
    // Ring of z-blurred rows (a and b interleaved by buffer), tagged by input y.
    std::vector<double> ringA(static_cast<std::size_t>(kTaps * nx));
    std::vector<double> ringB(static_cast<std::size_t>(kTaps * nx));
    std::int64_t tags[kTaps];
    std::vector<double> rowA(static_cast<std::size_t>(paddedX), 0.0);
    std::vector<double> rowB(static_cast<std::size_t>(paddedX), 0.0);
    for (std::int64_t zo = zBegin; zo < zEnd; ++zo)
    {
      if (control.stopped())
      {
        return;
      }
      const std::int64_t zc = zo * step;
      const double* wzo = &wz[zo * kTaps];
      std::int64_t zRows[kTaps]; // clipped taps read a valid row with weight 0
      for (int k = 0; k < kTaps; ++k)
      {
        zRows[k] = std::min(std::max<std::int64_t>(zc + k - kHalf, 0), n[2] - 1);
      }
      std::fill(tags, tags + kTaps, std::int64_t(-1));
      auto zRow = [&](std::int64_t y) -> int {
        const int slot = static_cast<int>(y % kTaps);
        if (tags[slot] != y)
        {
          source.blurRows(y, zRows, wzo, &ringA[slot * nx], &ringB[slot * nx], avx);
          tags[slot] = y;
        }
        return slot;
      };
      for (std::int64_t yo = 0; yo < m[1]; ++yo)
      {
        const std::int64_t yc = yo * step;
        const double* wyo = &wy[yo * kTaps];
        double* ra = rowA.data() + kHalf;
        double* rb = rowB.data() + kHalf;
        int slots[kTaps];
        for (int k = 0; k < kTaps; ++k)
        {
          slots[k] = zRow(std::min(std::max<std::int64_t>(yc + k - kHalf, 0), n[1] - 1));
        }
        {
          const double* ia[kTaps];
          const double* ib[kTaps];
          for (int k = 0; k < kTaps; ++k)
          {
            ia[k] = &ringA[slots[k] * nx];
            ib[k] = &ringB[slots[k] * nx];
          }
          VAO_VOM_DISPATCH(avx, yPass, (ia, ib, wyo, nx, ra, rb));
        }
        // x pass at the kept voxels; the padding is zero and so are the clipped weights.
        float* meanOut = out.mean.data() + (zo * m[1] + yo) * m[0];
        float* varOut = out.variance.data() + (zo * m[1] + yo) * m[0];
        const double* pa = rowA.data(); // pa[i + kHalf] = row value at input x = i
        const double* pb = rowB.data();
        // Interior (unclipped) voxels with the constant weights: a vectorisable loop.
        const std::int64_t interiorBegin = std::min<std::int64_t>(m[0], (kHalf + step - 1) / step);
        const std::int64_t interiorEnd = std::max<std::int64_t>(interiorBegin,
          std::min<std::int64_t>(m[0], (nx - 1 - kHalf) / step + 1));
        auto clipped = [&](std::int64_t xo) {
          const double* w = &wx[xo * kTaps];
          const std::int64_t base = xo * step; // = (xo * step - kHalf) + kHalf
          double sa = 0.0, sb = 0.0;
          for (int k = 0; k < kTaps; ++k)
          {
            sa += w[k] * pa[base + k];
            sb += w[k] * pb[base + k];
          }
          meanOut[xo] = static_cast<float>(sa + shift);
          varOut[xo] = static_cast<float>(std::max(0.0, sb - sa * sa));
        };
        for (std::int64_t xo = 0; xo < interiorBegin; ++xo)
        {
          clipped(xo);
        }
        if (step == 1)
        {
          VAO_VOM_DISPATCH(
            avx, xInterior, <1>(pa, pb, kernel, shift, interiorBegin, interiorEnd, meanOut, varOut));
        }
        else
        {
          VAO_VOM_DISPATCH(
            avx, xInterior, <2>(pa, pb, kernel, shift, interiorBegin, interiorEnd, meanOut, varOut));
        }
        for (std::int64_t xo = interiorEnd; xo < m[0]; ++xo)
        {
          clipped(xo);
        }
      }
      if (!control.advance(1, onCallingThread))
      {
        return;
      }
    }
  };
  const int chunks = static_cast<int>(std::min<std::int64_t>(m[2], std::max(1, threads) * 4));
  detail::parallelChunks(m[2], chunks, body, threads);
  return !control.stopped();
}

bool finite3(const double* p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

std::string pointMessage(const char* what, std::int64_t i)
{
  std::ostringstream s;
  s << what << " " << i;
  return s.str();
}

/// Checks the pyramid and resolves the number of levels used.
Status checkPyramid(const std::vector<MomentLevel>& pyramid, int requested, int& levels)
{
  if (pyramid.empty())
  {
    return Status::failure("the moment pyramid is empty (build it with buildMomentPyramid)");
  }
  for (const MomentLevel& level : pyramid)
  {
    const std::int64_t n = level.dims[0] * level.dims[1] * level.dims[2];
    if (level.dims[0] < 1 || level.dims[1] < 1 || level.dims[2] < 1 ||
      static_cast<std::int64_t>(level.mean.size()) != n ||
      static_cast<std::int64_t>(level.variance.size()) != n || !(level.kernelRadius > 0.0))
    {
      return Status::failure("a level of the moment pyramid is inconsistent (dims, arrays or radius)");
    }
  }
  const int available = static_cast<int>(pyramid.size());
  if (requested == -1)
  {
    levels = available;
  }
  else if (requested < 1 || requested > available)
  {
    std::ostringstream s;
    s << "levels must be -1 (all) or in [1, " << available << "], got " << requested;
    return Status::failure(s.str());
  }
  else
  {
    levels = requested;
  }
  return Status::success();
}

Status checkParameters(const SurfaceOcclusionParameters& p)
{
  if (!std::isfinite(p.offsetFactor) || p.offsetFactor < 0.0)
  {
    return Status::failure("offsetFactor must be finite and >= 0");
  }
  if (p.query == SurfaceQuery::IsoValue && !std::isfinite(p.isoValue))
  {
    return Status::failure("isoValue must be finite");
  }
  if (p.query != SurfaceQuery::IsoValue && p.query != SurfaceQuery::HalfVoxelInside)
  {
    return Status::failure("unknown surface query mode");
  }
  if (p.estimator != SurfaceEstimator::Chebyshev && p.estimator != SurfaceEstimator::GaussianCdf)
  {
    return Status::failure("unknown surface estimator");
  }
  if (p.combination != LevelCombination::MaximumOcclusion && p.combination != LevelCombination::Mean)
  {
    return Status::failure("unknown level combination");
  }
  return Status::success();
}

/// Validates points (finite) and normals (finite, non-zero).
Status checkPoints(const double* points, const double* normals, std::int64_t count)
{
  if (count < 0)
  {
    return Status::failure("the point count must be >= 0");
  }
  if (count > 0 && (!points || !normals))
  {
    return Status::failure("points and normals must not be null");
  }
  for (std::int64_t i = 0; i < count; ++i)
  {
    if (!finite3(points + 3 * i))
    {
      return Status::failure(pointMessage("non-finite coordinate at point", i));
    }
    const double* nn = normals + 3 * i;
    if (!finite3(nn))
    {
      return Status::failure(pointMessage("non-finite normal at point", i));
    }
    if (!(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2] > 0.0))
    {
      return Status::failure(pointMessage("zero normal at point", i));
    }
  }
  return Status::success();
}

std::array<double, 3> unit(const double* v)
{
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return { v[0] / l, v[1] / l, v[2] / l };
}

/// Trilinear value of the raw volume at a world position (clamped to its bounds).
template <class T>
double trilinear(const detail::TypedVolume<T>& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const std::array<double, 3>& position)
{
  std::int64_t i0[3], i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    const double maxIndex = static_cast<double>(volume.dims[a] - 1);
    const double u = std::min(std::max((position[a] - origin[a]) / spacing[a], 0.0), maxIndex);
    const double fl = std::floor(u);
    i0[a] = static_cast<std::int64_t>(fl);
    i1[a] = std::min<std::int64_t>(i0[a] + 1, volume.dims[a] - 1);
    f[a] = u - fl;
  }
  auto v = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<double>(volume.value(x, y, z));
  };
  const double c00 = v(i0[0], i0[1], i0[2]) * (1 - f[0]) + v(i1[0], i0[1], i0[2]) * f[0];
  const double c10 = v(i0[0], i1[1], i0[2]) * (1 - f[0]) + v(i1[0], i1[1], i0[2]) * f[0];
  const double c01 = v(i0[0], i0[1], i1[2]) * (1 - f[0]) + v(i1[0], i0[1], i1[2]) * f[0];
  const double c11 = v(i0[0], i1[1], i1[2]) * (1 - f[0]) + v(i1[0], i1[1], i1[2]) * f[0];
  const double c0 = c00 * (1 - f[1]) + c10 * f[1];
  const double c1 = c01 * (1 - f[1]) + c11 * f[1];
  return c0 * (1 - f[2]) + c1 * f[2];
}

double levelOcclusion(const MomentLevel& level, const std::array<double, 3>& position, double query,
  SurfaceEstimator estimator)
{
  double mean = 0.0, variance = 0.0;
  sampleLevel(level, position, mean, variance);
  const NeighbourhoodStats stats{ mean, variance, mean, mean };
  const double open = estimator == SurfaceEstimator::GaussianCdf
    ? opennessGaussianCdf(query, stats, ErfMode::Exact)
    : opennessChebyshev(query, stats);
  return 1.0 - open;
}

bool insideBounds(const MomentLevel& level, const std::array<double, 3>& p)
{
  const bool window = std::isfinite(level.wholeBounds[0]);
  for (int a = 0; a < 3; ++a)
  {
    const double lo = window ? level.wholeBounds[2 * a] : level.origin[a];
    const double hi =
      window ? level.wholeBounds[2 * a + 1] : level.origin[a] + (level.dims[a] - 1) * level.spacing[a];
    if (p[a] < lo || p[a] > hi)
    {
      return false;
    }
  }
  return true;
}

} // namespace

Status buildMomentPyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  std::vector<MomentLevel>& pyramid, const Execution& execution)
{
  auto fail = [&pyramid](std::string why) {
    pyramid.clear();
    return Status::failure(std::move(why));
  };
  if (!volume.data)
  {
    return fail("the volume has no data");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (volume.dims[a] < 2)
    {
      return fail("the volume must be 3-D with at least 2 voxels along every axis");
    }
    if (!std::isfinite(spacing[a]) || !(spacing[a] > 0.0))
    {
      return fail("the spacing must be finite and positive along every axis");
    }
    if (!std::isfinite(origin[a]))
    {
      return fail("the origin must be finite");
    }
  }
  if (volume.voxelStride < 1)
  {
    return fail("the voxel stride must be >= 1");
  }
  if (parameters.levels < 1 || parameters.levels > 16)
  {
    std::ostringstream s;
    s << "the number of pyramid levels must be in [1, 16], got " << parameters.levels;
    return fail(s.str());
  }
  std::int64_t firstBad = -1;
  if (countNonFinite(volume, &firstBad) > 0)
  {
    std::ostringstream s;
    s << "the volume holds non-finite values (first at voxel index " << firstBad
      << "); variance occlusion maps need finite data";
    return fail(s.str());
  }

  const int threads = detail::resolveThreadCount(execution.threads);
  const double shift = detail::dispatchScalarType(volume.type, [&](auto tag) {
    using T = decltype(tag);
    return detail::sampledMean(detail::TypedVolume<T>(volume));
  });

  const int levels = parameters.levels;
  // Reuse the storage of a previous build (same sizes: no allocation, no page faults).
  std::vector<MomentLevel> result = std::move(pyramid);
  pyramid.clear();
  result.resize(static_cast<std::size_t>(levels));
  const double stageWidth = 1.0 / levels;
  // Level 0 from the volume.
  {
    const int step = parameters.startAtHalfResolution ? 2 : 1;
    const Execution stage = detail::stageExecution(execution, 0.0, stageWidth);
    const bool done = detail::dispatchScalarType(volume.type, [&](auto tag) {
      using T = decltype(tag);
      const RawSource<T> source{ detail::TypedVolume<T>(volume), shift };
      return blurDecimate(source, step, shift, result[0], stage, threads);
    });
    if (!done)
    {
      return Status::cancelled();
    }
    result[0].origin = origin;
    for (int a = 0; a < 3; ++a)
    {
      result[0].spacing[a] = spacing[a] * step;
    }
  }
  for (int l = 1; l < levels; ++l)
  {
    const Execution stage = detail::stageExecution(execution, l * stageWidth, (l + 1) * stageWidth);
    const LevelSource source{ &result[l - 1], shift };
    if (!blurDecimate(source, 2, shift, result[l], stage, threads))
    {
      return Status::cancelled();
    }
    result[l].origin = result[l - 1].origin;
    for (int a = 0; a < 3; ++a)
    {
      result[l].spacing[a] = result[l - 1].spacing[a] * 2.0;
    }
  }
  for (MomentLevel& level : result)
  {
    // r_l: the 5-tap half-width (2 voxels) of the level's own grid, largest axis; it
    // doubles with every level.
    level.kernelRadius =
      2.0 * std::max(level.spacing[0], std::max(level.spacing[1], level.spacing[2]));
  }
  pyramid = std::move(result);
  return Status::success();
}

double sampleVolume(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const std::array<double, 3>& position)
{
  return detail::dispatchScalarType(volume.type, [&](auto tag) {
    using T = decltype(tag);
    return trilinear(detail::TypedVolume<T>(volume), origin, spacing, position);
  });
}

void sampleLevel(const MomentLevel& level, const std::array<double, 3>& position, double& mean, double& variance)
{
  std::int64_t i0[3], i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    const double maxIndex = static_cast<double>(level.dims[a] - 1);
    const double u =
      std::min(std::max((position[a] - level.origin[a]) / level.spacing[a], 0.0), maxIndex);
    const double fl = std::floor(u);
    i0[a] = static_cast<std::int64_t>(fl);
    i1[a] = std::min<std::int64_t>(i0[a] + 1, level.dims[a] - 1);
    f[a] = u - fl;
  }
  const std::int64_t nx = level.dims[0], ny = level.dims[1];
  double m = 0.0, v = 0.0;
  for (int c = 0; c < 8; ++c)
  {
    const std::int64_t x = (c & 1) ? i1[0] : i0[0];
    const std::int64_t y = (c & 2) ? i1[1] : i0[1];
    const std::int64_t z = (c & 4) ? i1[2] : i0[2];
    const double w = ((c & 1) ? f[0] : 1 - f[0]) * ((c & 2) ? f[1] : 1 - f[1]) *
      ((c & 4) ? f[2] : 1 - f[2]);
    const std::int64_t i = (z * ny + y) * nx + x;
    m += w * level.mean[i];
    v += w * level.variance[i];
  }
  mean = m;
  variance = std::max(0.0, v);
}

namespace
{

/// The checks both surface queries share: the pyramid and the levels used, the
/// parameters, the points and normals, and somewhere to write.
Status checkQuery(const std::vector<MomentLevel>& pyramid, const SurfaceOcclusionParameters& parameters,
  const double* points, const double* normals, std::int64_t count, const float* out, int& levels)
{
  Status status = checkPyramid(pyramid, parameters.levels, levels);
  if (status.ok)
    status = checkParameters(parameters);
  if (status.ok)
    status = checkPoints(points, normals, count);
  if (status.ok && count > 0 && !out)
    status = Status::failure("the output array must not be null");
  return status;
}

} // namespace

Status surfaceAmbientOcclusion(const std::vector<MomentLevel>& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters, float* out,
  const Execution& execution)
{
  int levels = 0;
  Status status = checkQuery(pyramid, parameters, points, normals, count, out, levels);
  if (!status.ok)
  {
    return status;
  }
  if (parameters.query == SurfaceQuery::HalfVoxelInside)
  {
    if (!volume.data || volume.dims[0] < 1 || volume.dims[1] < 1 || volume.dims[2] < 1 ||
      volume.voxelStride < 1)
    {
      return Status::failure("the half-voxel-inside query needs the volume");
    }
    for (int a = 0; a < 3; ++a)
    {
      if (!std::isfinite(spacing[a]) || !(spacing[a] > 0.0) || !std::isfinite(origin[a]))
      {
        return Status::failure("the volume's spacing must be finite and positive, its origin finite");
      }
    }
  }
  const double h = std::min(spacing[0], std::min(spacing[1], spacing[2]));
  const int threads = detail::resolveThreadCount(execution.threads);
  detail::LoopControl control(execution, count);

  auto run = [&](auto tag) {
    using T = decltype(tag);
    const bool half = parameters.query == SurfaceQuery::HalfVoxelInside;
    const detail::TypedVolume<T> typed(half ? volume : VolumeView{});
    auto body = [&](std::int64_t begin, std::int64_t end, bool onCallingThread) {
      for (std::int64_t i = begin; i < end; ++i)
      {
        const double* p = points + 3 * i;
        const std::array<double, 3> n = unit(normals + 3 * i);
        double query = parameters.isoValue;
        if (half)
        {
          const std::array<double, 3> inside = { p[0] - 0.5 * h * n[0], p[1] - 0.5 * h * n[1],
            p[2] - 0.5 * h * n[2] };
          query = trilinear(typed, origin, spacing, inside);
        }
        double combined = 0.0;
        for (int l = 0; l < levels; ++l)
        {
          const double offset = parameters.offsetFactor * pyramid[l].kernelRadius;
          const std::array<double, 3> at = { p[0] + offset * n[0], p[1] + offset * n[1],
            p[2] + offset * n[2] };
          const double occlusion = levelOcclusion(pyramid[l], at, query, parameters.estimator);
          combined = parameters.combination == LevelCombination::Mean
            ? combined + occlusion / levels
            : std::max(combined, occlusion);
        }
        out[i] = static_cast<float>(1.0 - clamp01(combined));
        if (((i - begin) & 1023) == 1023 && !control.advance(1024, onCallingThread))
        {
          return;
        }
      }
    };
    const int chunks = static_cast<int>(std::min<std::int64_t>(
      std::max<std::int64_t>(count, 1), std::max(1, threads) * 8));
    detail::parallelChunks(count, chunks, body, threads);
  };
  detail::dispatchScalarType(
    parameters.query == SurfaceQuery::HalfVoxelInside ? volume.type : ScalarType::Float32, run);
  if (control.stopped())
  {
    return Status::cancelled();
  }
  return Status::success();
}

Status surfaceShadow(const std::vector<MomentLevel>& pyramid, const double* points, const double* normals,
  std::int64_t count, const std::array<double, 3>& lightDirection, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution)
{
  int levels = 0;
  const Status status = checkQuery(pyramid, parameters, points, normals, count, out, levels);
  if (!status.ok)
  {
    return status;
  }
  if (!finite3(lightDirection.data()))
  {
    return Status::failure("the light direction must be finite");
  }
  const double lightLength = std::sqrt(lightDirection[0] * lightDirection[0] +
    lightDirection[1] * lightDirection[1] + lightDirection[2] * lightDirection[2]);
  if (!(lightLength > 0.0))
  {
    return Status::failure("the light direction must not be zero");
  }
  const std::array<double, 3> light = { lightDirection[0] / lightLength,
    lightDirection[1] / lightLength, lightDirection[2] / lightLength };
  const MomentLevel& base = pyramid[0];
  const double r0 = base.kernelRadius;
  const double h = std::min(base.spacing[0], std::min(base.spacing[1], base.spacing[2]));
  const int threads = detail::resolveThreadCount(execution.threads);
  detail::LoopControl control(execution, count);
  // Steps of half the level's radius: a blob of the level's size cannot fall between two.
  constexpr double kStepFraction = 0.5;
  constexpr int kMaxSteps = 1 << 16;

  auto body = [&](std::int64_t begin, std::int64_t end, bool onCallingThread) {
    for (std::int64_t i = begin; i < end; ++i)
    {
      const double* p = points + 3 * i;
      const std::array<double, 3> n = unit(normals + 3 * i);
      double query = parameters.isoValue;
      if (parameters.query == SurfaceQuery::HalfVoxelInside)
      {
        // No raw volume here: level 0's (blurred) mean half a voxel inside.
        double variance = 0.0;
        sampleLevel(base, { p[0] - 0.5 * h * n[0], p[1] - 0.5 * h * n[1], p[2] - 0.5 * h * n[2] },
          query, variance);
      }
      const std::array<double, 3> start = { p[0] + r0 * n[0], p[1] + r0 * n[1], p[2] + r0 * n[2] };
      double occlusion = 0.0;
      double t = 0.0;
      for (int s = 0; s < kMaxSteps; ++s)
      {
        const std::array<double, 3> at = { start[0] + t * light[0], start[1] + t * light[1],
          start[2] + t * light[2] };
        if (!insideBounds(base, at))
        {
          break;
        }
        const int l = std::min(levels - 1,
          std::max(0, static_cast<int>(std::floor(std::log2(1.0 + t / r0)))));
        occlusion =
          std::max(occlusion, levelOcclusion(pyramid[l], at, query, parameters.estimator));
        if (occlusion >= 0.999)
        {
          break;
        }
        t += kStepFraction * pyramid[l].kernelRadius;
      }
      out[i] = static_cast<float>(1.0 - clamp01(occlusion));
      if (((i - begin) & 255) == 255 && !control.advance(256, onCallingThread))
      {
        return;
      }
    }
  };
  const int chunks = static_cast<int>(
    std::min<std::int64_t>(std::max<std::int64_t>(count, 1), std::max(1, threads) * 8));
  detail::parallelChunks(count, chunks, body, threads);
  if (control.stopped())
  {
    return Status::cancelled();
  }
  return Status::success();
}

} // namespace vao
