// The GPU pipeline, written once for two executors: the CUDA one (CudaBackend.cu) runs
// each kernel as one GPU thread per index; the host emulator (tests) runs the same
// per-thread code in a loop, so the indexing of every pass is tested on machines without
// a GPU. No CUDA runtime calls here.
//
// Every pass runs along one axis with one thread per "lane" (a line of voxels along the
// axis) and adjacent threads on adjacent voxels, so loads and stores are coalesced. The
// x axis is contiguous in memory, so the x passes run on a transposed copy (x and y
// swapped per slice) and transpose back. Each pass is O(1) per voxel whatever the radius:
// running sums for the moments, van Herk / Gil-Werman blocks for the extrema. The last
// (z) pass evaluates the estimator (Estimators.h, the formulas the CPU uses) in place, so
// the statistics themselves are never written out for the openness.
#pragma once

#include "cuda/common/AxisPasses.h"
#include "cuda/common/VanHerkPasses.h"

#include <algorithm>
#include <cstdint>

namespace vao
{
namespace gpu
{

/// What the last pass writes (null: not asked for): openness and variance (float) or the
/// statistics (double).
struct FinalOutputs
{
  float* openness;
  float* variance;
  double* count;
  double* mean;
  double* varianceD;
  double* minimum;
  double* maximum;
};

/// Geometry of the computation: the block the region reads, and the region inside it.
struct RegionGeometry
{
  Index sx, sy, sz; // the uploaded block (the spans the region reads)
  Index ox, oy, oz; // the region's origin inside it
  Index rx, ry, rz; // the region's size
  Index radius[3];

  VAO_HD Index block() const { return sx * sy * sz; }
  VAO_HD Index afterX() const { return rx * sy * sz; } // region width, spans in y and z
  VAO_HD Index afterY() const { return rx * ry * sz; }
  VAO_HD Index region() const { return rx * ry * rz; }
};

/// The block a region reads (its spans grown by the radius, clipped to the volume) and
/// the region inside it. Windows clipped to the block are those clipped to the volume.
inline RegionGeometry geometryFor(const Index3& dims, const Region& region, const Radius& radius)
{
  const int r[3] = { radius.x, radius.y, radius.z };
  Index lo[3], size[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = std::max<Index>(0, region.begin[a] - r[a]);
    size[a] = std::min<Index>(dims[a], region.begin[a] + region.size[a] + r[a]) - lo[a];
  }
  return RegionGeometry{ size[0], size[1], size[2], region.begin[0] - lo[0],
    region.begin[1] - lo[1], region.begin[2] - lo[2], region.size[0], region.size[1],
    region.size[2], { r[0], r[1], r[2] } };
}

/// What to compute: the estimator and its query (ignored for the statistics).
struct EstimatorSetting
{
  Method method;
  QueryMode query;
  double isoValue;
  ErfMode erfMode;
  double roundingVariance = 0.0; // of the moment sums (MomentScale)
  MomentBasis basis;             // the data set's, for a piece of it (AmbientOcclusion.h)
};

/// Running sums along z of two x-y box sums ([sz][ry][rx]) for one thread of a z pass:
/// one (x, y) column of the region and a segment of its slices; visit(index, z, x, y, s1,
/// s2) gets each voxel's box sums (index in the region, x fastest; z in the block).
template <class Acc, class Visit>
VAO_HD void zRunningSums(const Acc* sum1, const Acc* sum2, const RegionGeometry& g, Index segment,
  Index thread, Visit&& visit)
{
  const Index lanes = g.rx * g.ry;
  const Index lane = thread % lanes;
  const Index x = lane % g.rx, y = lane / g.rx;
  const Index first = (thread / lanes) * segment;
  const Index last = lower(first + segment, g.rz);
  const Index r = g.radius[2];
  const Index lo = greater(Index(0), g.oz + first - r), hi = lower(g.sz - 1, g.oz + first + r);
  Acc s1 = 0, s2 = 0;
  for (Index j = lo; j <= hi; ++j)
  {
    s1 += sum1[j * lanes + lane];
    s2 += sum2[j * lanes + lane];
  }
  for (Index k = first; k < last; ++k)
  {
    const Index z = g.oz + k;
    visit(k * lanes + lane, z, x, y, s1, s2);
    if (z + r + 1 <= g.sz - 1)
    {
      s1 += sum1[(z + r + 1) * lanes + lane];
      s2 += sum2[(z + r + 1) * lanes + lane];
    }
    if (z - r >= 0)
    {
      s1 -= sum1[(z - r) * lanes + lane];
      s2 -= sum2[(z - r) * lanes + lane];
    }
  }
}

/// What a pass that ends with a voxel's box sums does with them: the mean and variance,
/// then the estimator's openness (Estimators.h, the CPU's formulas) or the statistics,
/// into whichever outputs are asked for. Shared by the z pass and the fused pass.
template <class T, class Acc>
struct StatisticsWriter
{
  const T* extremaMin; // box extrema of the region, or null
  const T* extremaMax;
  const T* input; // the uploaded block, for the voxel-value query
  RegionGeometry g;
  Acc shift;
  EstimatorSetting estimator;
  FinalOutputs out;

  /// Voxel (x, y) of the region in block slice z: how many voxels its clipped box holds.
  VAO_HD long long count(Index x, Index y, Index z) const
  {
    return clippedWindowCount(g.ox + x, g.radius[0], g.sx) *
      clippedWindowCount(g.oy + y, g.radius[1], g.sy) * clippedWindowCount(z, g.radius[2], g.sz);
  }

  /// With the extrema from extremaMin/Max (the separate passes) or none.
  VAO_HD void write(Index index, Index z, Index x, Index y, Acc s1, Acc s2) const
  {
    this->write(index, z, x, y, s1, s2, extremaMin ? static_cast<double>(extremaMin[index]) : 0.0,
      extremaMax ? static_cast<double>(extremaMax[index]) : 0.0);
  }

  VAO_HD void write(
    Index index, Index z, Index x, Index y, Acc s1, Acc s2, double minimum, double maximum) const
  {
    const long long n = this->count(x, y, z);
    NeighbourhoodStats s{ 0.0, 0.0, minimum, maximum, estimator.roundingVariance };
    meanVarianceFromSums(s1, s2, n, static_cast<double>(shift), s.mean, s.variance);
    if (out.openness)
    {
      const double q = estimator.query == QueryMode::VoxelValue
        ? static_cast<double>(input[(z * g.sy + g.oy + y) * g.sx + g.ox + x])
        : estimator.isoValue;
      out.openness[index] =
        static_cast<float>(opennessFromStats(estimator.method, q, s, estimator.erfMode));
    }
    if (out.variance)
      out.variance[index] = static_cast<float>(reportedVariance(s.variance, s.roundingVariance));
    if (out.count)
      out.count[index] = static_cast<double>(n);
    if (out.mean)
      out.mean[index] = s.mean;
    if (out.varianceD)
      out.varianceD[index] = s.variance;
    if (out.minimum)
      out.minimum[index] = s.minimum;
    if (out.maximum)
      out.maximum[index] = s.maximum;
  }

  /// Bytes the outputs take per voxel.
  double bytesPerVoxel() const
  {
    return (out.openness ? 4.0 : 0.0) + (out.variance ? 4.0 : 0.0) +
      8.0 *
      ((out.count != nullptr) + (out.mean != nullptr) + (out.varianceD != nullptr) +
        (out.minimum != nullptr) + (out.maximum != nullptr));
  }
};

/// The z pass fused with the estimator: one thread per (x, y) column of the region and
/// segment of slices; running sums of both moments along z, then the writer.
template <class T, class Acc>
struct FinalKernel
{
  const Acc* sum1; // x and y box sums, [sz][ry][rx]
  const Acc* sum2;
  StatisticsWriter<T, Acc> writer;
  Index segment;

  VAO_HD Index threads() const
  {
    return writer.g.rx * writer.g.ry * segmentsOf(writer.g.rz, segment);
  }

  VAO_HD void operator()(Index thread) const
  {
    zRunningSums(sum1, sum2, writer.g, segment, thread,
      [&](Index index, Index z, Index x, Index y, Acc s1, Acc s2)
      { writer.write(index, z, x, y, s1, s2); });
  }
};

/// The passes in order, on an executor that provides:
///   Buffer<U> allocate<U>(Index count)          (.get() gives the pointer)
///   void launch(const Kernel& k, const char* name, double bytes)   runs k(t), t < k.threads()
///   void transpose(const U* in, U* out, Index nx, Index ny, Index nz, const char* name)
///   void progress(double fraction)              (may throw to cancel)
/// `input` is the uploaded block (g.block() values); `out` points to executor memory.
template <class T, class Acc, class Executor>
void runPasses(Executor& ex, const T* input, const RegionGeometry& g, bool withExtrema, Acc shift,
  const EstimatorSetting& estimator, const FinalOutputs& out)
{
  const AxisPass xPass{ g.sy * g.sz, g.sx, g.radius[0], g.ox, g.rx,
    LaneLayout{ g.sy, g.sx * g.sy, g.sy }, LaneLayout{ g.sy, g.rx * g.sy, g.sy } };
  const AxisPass yPass{ g.rx * g.sz, g.sy, g.radius[1], g.oy, g.ry,
    LaneLayout{ g.rx, g.sy * g.rx, g.rx }, LaneLayout{ g.rx, g.ry * g.rx, g.rx } };
  const AxisPass zPass{ g.rx * g.ry, g.sz, g.radius[2], g.oz, g.rz,
    LaneLayout{ g.rx * g.ry, 0, g.rx * g.ry }, LaneLayout{ g.rx * g.ry, 0, g.rx * g.ry } };

  // x passes run on the transposed block: lanes are (y, z), x is the axis.
  auto transposed = ex.template allocate<T>(g.block());
  ex.transpose(input, transposed.get(), g.sx, g.sy, g.sz, "transpose input");

  // Moments along x and y; z in the final pass.
  auto a1 = ex.template allocate<Acc>(g.afterX()), a2 = ex.template allocate<Acc>(g.afterX());
  auto b1 = ex.template allocate<Acc>(g.afterX()), b2 = ex.template allocate<Acc>(g.afterX());
  const MomentKernel<T, Acc, true> momentsX{ { transposed.get(), nullptr, shift }, a1.get(),
    a2.get(), xPass, segmentLength(xPass.r) };
  ex.launch(momentsX, "moments x", g.block() * sizeof(T) + 2.0 * g.afterX() * sizeof(Acc));
  ex.transpose(a1.get(), b1.get(), g.sy, g.rx, g.sz, "transpose moments"); // -> [z][y][x]
  ex.transpose(a2.get(), b2.get(), g.sy, g.rx, g.sz, "transpose moments");
  const MomentKernel<Acc, Acc, false> momentsY{ { b1.get(), b2.get(), Acc(0) }, a1.get(), a2.get(),
    yPass, segmentLength(yPass.r) };
  ex.launch(momentsY, "moments y", 2.0 * (g.afterX() + g.afterY()) * sizeof(Acc));
  ex.progress(0.4);

  // Extrema (CDF Reconstruction, statistics): the same three axes with van Herk blocks.
  // x: transposed -> e (suffixes in f), transpose e -> f, y: f -> e, z: e -> f.
  const Index room = withExtrema ? (g.block() > g.afterX() ? g.block() : g.afterX()) : 0;
  auto e1 = ex.template allocate<T>(withExtrema ? g.afterX() : 0),
       e2 = ex.template allocate<T>(withExtrema ? g.afterX() : 0);
  auto f1 = ex.template allocate<T>(room), f2 = ex.template allocate<T>(room);
  auto s1 = ex.template allocate<T>(withExtrema ? g.afterX() : 0),
       s2 = ex.template allocate<T>(withExtrema ? g.afterX() : 0);
  if (withExtrema)
  {
    ex.launch(VanHerkKernel<T, VanHerkStep::Suffix>{ transposed.get(), transposed.get(), f1.get(),
                f2.get(), nullptr, nullptr, xPass },
      "extrema x suffix", 3.0 * g.block() * sizeof(T));
    ex.launch(VanHerkKernel<T, VanHerkStep::Output>{ transposed.get(), transposed.get(), f1.get(),
                f2.get(), e1.get(), e2.get(), xPass },
      "extrema x", 2.0 * g.block() * sizeof(T) + 2.0 * g.afterX() * sizeof(T));
    ex.transpose(e1.get(), f1.get(), g.sy, g.rx, g.sz, "transpose extrema");
    ex.transpose(e2.get(), f2.get(), g.sy, g.rx, g.sz, "transpose extrema");
    ex.launch(VanHerkKernel<T, VanHerkStep::Suffix>{ f1.get(), f2.get(), s1.get(), s2.get(),
                nullptr, nullptr, yPass },
      "extrema y suffix", 4.0 * g.afterX() * sizeof(T));
    ex.launch(VanHerkKernel<T, VanHerkStep::Output>{ f1.get(), f2.get(), s1.get(), s2.get(),
                e1.get(), e2.get(), yPass },
      "extrema y", 4.0 * g.afterX() * sizeof(T) + 2.0 * g.afterY() * sizeof(T));
    ex.launch(VanHerkKernel<T, VanHerkStep::Suffix>{ e1.get(), e2.get(), s1.get(), s2.get(),
                nullptr, nullptr, zPass },
      "extrema z suffix", 4.0 * g.afterY() * sizeof(T));
    ex.launch(VanHerkKernel<T, VanHerkStep::Output>{ e1.get(), e2.get(), s1.get(), s2.get(),
                f1.get(), f2.get(), zPass },
      "extrema z", 4.0 * g.afterY() * sizeof(T) + 2.0 * g.region() * sizeof(T));
  }
  ex.progress(0.6);

  const StatisticsWriter<T, Acc> writer{ withExtrema ? f1.get() : nullptr,
    withExtrema ? f2.get() : nullptr, input, g, shift, estimator, out };
  const FinalKernel<T, Acc> final{ a1.get(), a2.get(), writer, segmentLength(g.radius[2]) };
  ex.launch(final, "z + estimator",
    2.0 * g.afterY() * sizeof(Acc) +
      g.region() * (sizeof(T) * (withExtrema ? 3.0 : 1.0) + writer.bytesPerVoxel()));
  ex.progress(0.9);
}

} // namespace gpu
} // namespace vao
