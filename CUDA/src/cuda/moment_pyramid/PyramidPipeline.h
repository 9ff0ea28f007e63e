// The moment pyramid on the device (vao/VarianceOcclusionMap.h; docs/methods.md,
// Penner and Mitchell). Each level is PyramidBuild.cxx's blur as three passes of one
// thread per output value: along z from the source (the raw volume or the previous level)
// into two double arrays, along y, and along x into the level's float mean and variance.
// Every sum is BlurTaps.h's, as the CPU's rows (PyramidRows.h) take them, with the same
// clipped weights (axisWeights; a tap outside the volume reads a clamped voxel with weight 0).
// Written once for the CUDA executor and the host emulation of the tests; no CUDA runtime
// calls here.
#pragma once

#include "BlurTaps.h"
#include "cpu/moment_pyramid/PyramidPlan.h"
#include "cuda/common/Pipeline.h"

#include <vector>

namespace vao
{
namespace gpu
{

using blur::kTaps;

/// Input index of tap k of kept output o along an axis of n voxels, clamped.
VAO_HD Index blurTap(Index o, int step, int k, Index n)
{
  return lower<Index>(greater<Index>(o * step + k - blur::kHalf, 0), n - 1);
}

/// z pass from the raw volume (nx * ny * nz values, x fastest): a = sum w d, b = sum w d^2
/// with d = v - shift, into arrays of (nx, ny, oz).
template <class T>
struct BlurRawZ
{
  const T* v;
  Index nx, ny, nz, oz;
  int step;
  const double* wz; // 5 per kept z
  double shift;
  double* a;
  double* b;

  VAO_HD Index threads() const { return nx * ny * oz; }
  VAO_HD void operator()(Index t) const
  {
    const Index x = t % nx, y = (t / nx) % ny, zo = t / (nx * ny);
    const double* w = wz + zo * kTaps;
    double d[kTaps];
    for (int k = 0; k < kTaps; ++k)
      d[k] = static_cast<double>(v[(blurTap(zo, step, k, nz) * ny + y) * nx + x]) - shift;
    a[t] = blur::tapSum(w, d);
    b[t] = blur::squareSum(w, d);
  }
};

/// A pass along `axis` of a grid of both moments: input (n[0], n[1], n[2]) into output
/// (the same, `kept` values along `axis`). at(i, u, v) loads the pair of input voxel i (its
/// linear index); put(t, a, b) stores the tap sums of output t.
template <class At, class Put>
struct AxisBlur
{
  Index n[3];
  int axis;
  Index kept;
  int step;
  const double* weights; // kTaps per kept output
  At at;
  Put put;

  VAO_HD Index threads() const
  {
    Index count = kept;
    for (int c = 0; c < 3; ++c)
      count *= c == axis ? 1 : n[c];
    return count;
  }
  VAO_HD void operator()(Index t) const
  {
    Index outDims[3] = { n[0], n[1], n[2] };
    outDims[axis] = kept;
    Index c[3] = { t % outDims[0], (t / outDims[0]) % outDims[1], t / (outDims[0] * outDims[1]) };
    const Index o = c[axis];
    const double* w = weights + o * kTaps;
    double u[kTaps], v[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      c[axis] = blurTap(o, step, k, n[axis]);
      at((c[2] * n[1] + c[1]) * n[0] + c[0], u[k], v[k]);
    }
    put(t, blur::tapSum(w, u), blur::tapSum(w, v));
  }
};

template <class At, class Put>
AxisBlur<At, Put> axisBlur(
  const Index n[3], int axis, Index kept, int step, const double* weights, At at, Put put)
{
  return { { n[0], n[1], n[2] }, axis, kept, step, weights, at, put };
}

/// Where a pass's tap sums go: the a and b arrays of the next pass.
struct PutPair
{
  double* a;
  double* b;
  VAO_HD void operator()(Index t, double sa, double sb) const
  {
    a[t] = sa;
    b[t] = sb;
  }
};

/// z pass from a stored level: d = mean - shift, s = variance + d^2.
struct LevelPair
{
  const float* mean;
  const float* variance;
  double shift;
  VAO_HD void operator()(Index i, double& d, double& s) const
  {
    d = static_cast<double>(mean[i]) - shift;
    s = static_cast<double>(variance[i]) + d * d;
  }
};

/// y pass: the z pass's two arrays as they are.
struct ArrayPair
{
  const double* a;
  const double* b;
  VAO_HD void operator()(Index i, double& u, double& v) const
  {
    u = a[i];
    v = b[i];
  }
};

/// x pass: into the level's mean = A + shift and variance = max(0, B - A^2), as float.
struct PutMoments
{
  double shift;
  float* mean;
  float* variance;
  VAO_HD void operator()(Index t, double a, double b) const
  {
    blur::levelMoments(a, b, shift, mean[t], variance[t]);
  }
};

/// One level's three passes: `z` (BlurRawZ, or the z AxisBlur of a stored level; its
/// output the arrays za, zb) then y and x into mean and variance of `out` kept voxels. The
/// y arrays hold (nx, oy, oz).
template <class Executor, class ZPass>
void runBlurLevel(Executor& ex, const ZPass& z, const double* za, const double* zb,
  const Index in[3], const Index out[3], int step, const double* wy, const double* wx, double shift,
  double* ya, double* yb, float* mean, float* variance)
{
  ex.launch(z, "pyramid z", static_cast<double>(z.threads()) * 16.0);
  const Index zDims[3] = { in[0], in[1], out[2] }, yDims[3] = { in[0], out[1], out[2] };
  const auto y = axisBlur(zDims, 1, out[1], step, wy, ArrayPair{ za, zb }, PutPair{ ya, yb });
  ex.launch(y, "pyramid y", static_cast<double>(y.threads()) * 16.0 * 2.0);
  const auto x =
    axisBlur(yDims, 0, out[0], step, wx, ArrayPair{ ya, yb }, PutMoments{ shift, mean, variance });
  ex.launch(x, "pyramid x",
    static_cast<double>(x.threads()) * 8.0 + static_cast<double>(y.threads()) * 16.0);
}

/// Every level of the pyramid from the raw volume `v` (dims, x fastest) into `out`'s
/// dims, means and variances, as PyramidBuild.cxx builds it (PyramidPlan.h's kept voxels
/// and clipped weights; the geometry is setLevelGeometry's): level 0 keeps every
/// setup.firstStep-th voxel, the next ones every second, each built from the one before.
template <class T, class Executor>
void runPyramid(Executor& ex, const T* v, const Index3& dims, const detail::PyramidSetup& setup,
  int levels, std::vector<MomentLevel>& out)
{
  out.resize(static_cast<std::size_t>(levels));
  Index3 in = dims;
  auto sourceMean = ex.template allocate<float>(0);
  auto sourceVariance = ex.template allocate<float>(0);
  for (int l = 0; l < levels; ++l)
  {
    const int step = l == 0 ? setup.firstStep : 2;
    const Index3 kept = detail::keptDims(in, step);
    const Index i[3] = { in[0], in[1], in[2] }, o[3] = { kept[0], kept[1], kept[2] };
    const auto hx = detail::axisWeights(i[0], o[0], step),
               hy = detail::axisWeights(i[1], o[1], step),
               hz = detail::axisWeights(i[2], o[2], step);
    const auto wx = ex.upload(hx.data(), static_cast<Index>(hx.size()));
    const auto wy = ex.upload(hy.data(), static_cast<Index>(hy.size()));
    const auto wz = ex.upload(hz.data(), static_cast<Index>(hz.size()));
    auto za = ex.template allocate<double>(i[0] * i[1] * o[2]);
    auto zb = ex.template allocate<double>(i[0] * i[1] * o[2]);
    auto ya = ex.template allocate<double>(i[0] * o[1] * o[2]);
    auto yb = ex.template allocate<double>(i[0] * o[1] * o[2]);
    const Index count = o[0] * o[1] * o[2];
    auto mean = ex.template allocate<float>(count);
    auto variance = ex.template allocate<float>(count);
    const double shift = setup.shift;
    if (l == 0)
      runBlurLevel(ex,
        BlurRawZ<T>{ v, i[0], i[1], i[2], o[2], step, wz.get(), shift, za.get(), zb.get() },
        za.get(), zb.get(), i, o, step, wy.get(), wx.get(), shift, ya.get(), yb.get(), mean.get(),
        variance.get());
    else
      runBlurLevel(ex,
        axisBlur(i, 2, o[2], step, wz.get(),
          LevelPair{ sourceMean.get(), sourceVariance.get(), shift },
          PutPair{ za.get(), zb.get() }),
        za.get(), zb.get(), i, o, step, wy.get(), wx.get(), shift, ya.get(), yb.get(), mean.get(),
        variance.get());
    MomentLevel& level = out[static_cast<std::size_t>(l)];
    level.dims = kept;
    level.mean.resize(static_cast<std::size_t>(count));
    level.variance.resize(static_cast<std::size_t>(count));
    ex.download(level.mean.data(), mean.get(), count);
    ex.download(level.variance.data(), variance.get(), count);
    ex.progress(0.1 + 0.9 * (l + 1) / levels);
    sourceMean = std::move(mean); // the next level's source
    sourceVariance = std::move(variance);
    in = kept;
  }
}

} // namespace gpu
} // namespace vao
