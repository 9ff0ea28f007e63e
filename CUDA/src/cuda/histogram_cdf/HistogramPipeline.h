// Histogram CDF on the GPU, written once for the CUDA executor and the host emulator (see
// Pipeline.h). Each voxel gets its bin (thresholdIndex of its value) and each region voxel
// the bin of its query; then, two thresholds at a time, the box counts of the indicators
// [bin <= k] and [bin <= k + 1] go through the moments' fused pass (FusedStatistics.h;
// where the tile does not fit a block, their running-sum passes: x on the transposed bins,
// y, then z), which keeps, per voxel, the counts at the two thresholds that enclose its
// query. The last kernel applies the formula of Estimators.h (opennessHistogramCdfAt),
// the one the CPU uses. Every pass is O(1) per voxel whatever the radius; there are K/2
// rounds (one fused pass each, or three).
#pragma once

#include "cuda/common/FusedStatistics.h"
#include "cuda/common/Pipeline.h"

namespace vao
{
namespace gpu
{

using Bin = unsigned short; // thresholdIndex of a value: 0..1024

/// The first-pass source: the two indicators of a voxel's bin.
struct IndicatorSource
{
  const Bin* bins;
  int k;

  VAO_HD void load(Index index, int& v1, int& v2) const
  {
    const int b = bins[index];
    v1 = b <= k ? 1 : 0;
    v2 = b <= k + 1 ? 1 : 0;
  }
};

/// bins[i] = thresholdIndex of input[i] over the block.
template <class T>
struct BinKernel
{
  const T* input;
  const double* thresholds;
  int n;
  Bin* bins;
  Index count;

  VAO_HD Index threads() const { return count; }
  VAO_HD void operator()(Index i) const
  {
    bins[i] = static_cast<Bin>(thresholdIndex(static_cast<double>(input[i]), thresholds, n));
  }
};

/// What the first and the last kernel read of the query: the uploaded block, the region
/// in it, the iso value (when iso) and the n thresholds in device memory.
template <class T>
struct HistogramQuerySource
{
  const T* input;
  RegionGeometry g;
  bool iso;
  double isoValue;
  const double* thresholds;
  int n;

  /// The query of region voxel `index` (x fastest): its value in the block, or the iso value.
  VAO_HD double at(Index index) const
  {
    const Index x = index % g.rx, y = (index / g.rx) % g.ry, z = index / (g.rx * g.ry);
    return iso ? isoValue
               : static_cast<double>(input[((g.oz + z) * g.sy + g.oy + y) * g.sx + g.ox + x]);
  }
};

/// upper[i] = thresholdIndex of region voxel i's query; below and atOrBelow start at 0.
template <class T>
struct UpperKernel
{
  HistogramQuerySource<T> query;
  int* upper;
  int* below;
  int* atOrBelow;

  VAO_HD Index threads() const { return query.g.region(); }
  VAO_HD void operator()(Index i) const
  {
    upper[i] = thresholdIndex(query.at(i), query.thresholds, query.n);
    below[i] = 0;
    atOrBelow[i] = 0;
  }
};

/// What round k keeps of a voxel's box counts of [bin <= k] (s1) and [bin <= k + 1] (s2):
/// the count at t_(upper-1) (below) and at t_upper (atOrBelow), when the round holds them.
struct GatherSink
{
  const int* upper;
  int* below;
  int* atOrBelow;
  int k;

  VAO_HD void write(Index index, Index, Index, Index, int s1, int s2) const
  {
    const int u = upper[index];
    if (u - 1 == k)
      below[index] = s1;
    else if (u - 1 == k + 1)
      below[index] = s2;
    if (u == k)
      atOrBelow[index] = s1;
    else if (u == k + 1)
      atOrBelow[index] = s2;
  }
};

/// The z pass of round k: running sums of both indicators' x-y box counts along z, into
/// the GatherSink.
struct GatherKernel
{
  const int* sum1; // x and y box counts of [bin <= k], [sz][ry][rx]
  const int* sum2; // of [bin <= k + 1]
  GatherSink sink;
  RegionGeometry g;
  Index segment;

  VAO_HD Index threads() const { return g.rx * g.ry * segmentsOf(g.rz, segment); }

  VAO_HD void operator()(Index thread) const
  {
    zRunningSums(sum1, sum2, g, segment, thread,
      [&](Index index, Index z, Index x, Index y, int s1, int s2)
      { sink.write(index, z, x, y, s1, s2); });
  }
};

/// The openness of every region voxel from its two counts.
template <class T>
struct HistogramOpennessKernel
{
  HistogramQuerySource<T> query;
  const int* upper;
  const int* below;
  const int* atOrBelow;
  float* openness;

  VAO_HD Index threads() const { return query.g.region(); }
  VAO_HD void operator()(Index i) const
  {
    const RegionGeometry& g = query.g;
    const Index x = i % g.rx, y = (i / g.rx) % g.ry, z = i / (g.rx * g.ry);
    const double count = static_cast<double>(clippedWindowCount(g.ox + x, g.radius[0], g.sx)) *
      static_cast<double>(clippedWindowCount(g.oy + y, g.radius[1], g.sy)) *
      static_cast<double>(clippedWindowCount(g.oz + z, g.radius[2], g.sz));
    const int u = upper[i];
    const double at = u < query.n ? static_cast<double>(atOrBelow[i] - below[i]) : 0.0;
    openness[i] = static_cast<float>(opennessHistogramCdfAt(
      query.at(i), query.thresholds, query.n, u, count, static_cast<double>(below[i]), at));
  }
};

/// Histogram CDF's passes on an executor of Pipeline.h's kind that also provides
///   Buffer<U> upload<U>(const U* host, Index count)   (a device copy of host values)
///   Index sharedLimit()                               (shared memory a block may have)
///   void launchBlocks(const Kernel& k, const char* name, double bytes)   (FusedStatistics.h)
/// `input` is the uploaded block; `openness` executor memory of g.region() floats. Each
/// round is one fused pass of the indicators (FusedStatistics.h) where its tile fits a
/// block, else x, y and z passes.
template <class T, class Executor>
void runHistogramPasses(Executor& ex, const T* input, const RegionGeometry& g,
  const double* hostThresholds, int n, bool iso, double isoValue, float* openness)
{
  const bool fused = fusedPassFits<int, Bin>(g, false, ex.sharedLimit());
  auto thresholds = ex.template upload<double>(hostThresholds, n);
  auto bins = ex.template allocate<Bin>(g.block()),
       transposed = ex.template allocate<Bin>(fused ? 0 : g.block());
  ex.launch(BinKernel<T>{ input, thresholds.get(), n, bins.get(), g.block() }, "bins",
    g.block() * (sizeof(T) + sizeof(Bin)));
  auto upper = ex.template allocate<int>(g.region()), below = ex.template allocate<int>(g.region()),
       atOrBelow = ex.template allocate<int>(g.region());
  const HistogramQuerySource<T> query{ input, g, iso, isoValue, thresholds.get(), n };
  ex.launch(UpperKernel<T>{ query, upper.get(), below.get(), atOrBelow.get() }, "query bins",
    g.region() * (sizeof(T) + 3.0 * sizeof(int)));

  const Index afterX = fused ? 0 : g.afterX();
  auto a1 = ex.template allocate<int>(afterX), a2 = ex.template allocate<int>(afterX);
  auto b1 = ex.template allocate<int>(afterX), b2 = ex.template allocate<int>(afterX);
  if (!fused)
    ex.transpose(bins.get(), transposed.get(), g.sx, g.sy, g.sz, "transpose bins");
  const AxisPass xPass{ g.sy * g.sz, g.sx, g.radius[0], g.ox, g.rx,
    LaneLayout{ g.sy, g.sx * g.sy, g.sy }, LaneLayout{ g.sy, g.rx * g.sy, g.sy } };
  const AxisPass yPass{ g.rx * g.sz, g.sy, g.radius[1], g.oy, g.ry,
    LaneLayout{ g.rx, g.sy * g.rx, g.rx }, LaneLayout{ g.rx, g.ry * g.rx, g.rx } };
  for (int k = 0; k < n; k += 2)
  {
    const GatherSink sink{ upper.get(), below.get(), atOrBelow.get(), k };
    if (fused)
    {
      const FusedBoxSums<IndicatorSource, GatherSink, int> counts{ { bins.get(), k }, sink, g, 0,
        g.rz, segmentLength(g.radius[2]) };
      ex.launchBlocks(
        counts, "indicators (fused)", g.block() * sizeof(Bin) + 3.0 * g.region() * sizeof(int));
    }
    else
    {
      const SumKernel<IndicatorSource, int> countsX{ { transposed.get(), k }, a1.get(), a2.get(),
        xPass, segmentLength(xPass.r) };
      ex.launch(countsX, "indicators x", g.block() * sizeof(Bin) + 2.0 * g.afterX() * sizeof(int));
      ex.transpose(a1.get(), b1.get(), g.sy, g.rx, g.sz, "transpose counts");
      ex.transpose(a2.get(), b2.get(), g.sy, g.rx, g.sz, "transpose counts");
      const MomentKernel<int, int, false> countsY{ { b1.get(), b2.get(), 0 }, a1.get(), a2.get(),
        yPass, segmentLength(yPass.r) };
      ex.launch(countsY, "indicators y", 2.0 * (g.afterX() + g.afterY()) * sizeof(int));
      ex.launch(GatherKernel{ a1.get(), a2.get(), sink, g, segmentLength(g.radius[2]) },
        "indicators z", 2.0 * g.afterY() * sizeof(int) + 3.0 * g.region() * sizeof(int));
    }
    ex.progress(0.1 + 0.8 * lower(1.0, (k + 2.0) / n));
  }
  ex.launch(
    HistogramOpennessKernel<T>{ query, upper.get(), below.get(), atOrBelow.get(), openness },
    "openness", g.region() * (sizeof(T) + 3.0 * sizeof(int) + sizeof(float)));
}

} // namespace gpu
} // namespace vao
