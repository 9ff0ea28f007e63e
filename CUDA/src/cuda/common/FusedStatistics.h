// The fused statistics pass of the device: the box sums of both moments and the estimator
// in one kernel ("2.5-D blocking"), instead of Pipeline.h's x, y and z passes with their
// transposes and four full-size intermediate arrays.
//
// A thread block owns a tile of kTileX x kTileY output columns and a segment of slices.
// For each input slice it loads the tile with its x-y halo into shared memory, sums rows
// (a running window along x, one thread per row), then columns (a running window along y,
// one thread per column): each column's x-y box sums of that slice. A column's z running
// sum, one per thread, adds the slice entering its window and subtracts the one leaving
// it, which is summed again then (twice the x-y work, but no ring of 2 r + 1 slices whose
// size would grow with the radius). Every step is O(1) per voxel whatever the radius, and
// the only traffic to memory is the input (from cache, (1 + 2 rx / 32)(1 + 2 ry / 8) times
// per slice) and the outputs, written once.
//
// The block's code is written once against a Block that runs a phase for every item and
// then waits for all of them: on the device a strided loop over the block's threads and
// __syncthreads() (CudaExecutor.h), on the host a loop (the tests' host twin, which also
// runs the items backwards to show that no phase reads what another item of the same
// phase writes). Every branch around a phase depends on the block only, so every thread
// reaches every barrier.
#pragma once

#include "cuda/common/FusedExtrema.h"
#include "cuda/common/FusedTile.h"
#include "cuda/common/Pipeline.h"

namespace vao
{
namespace gpu
{

/// The shared memory of one block, in accumulators: the loaded slice with its halo (two
/// moments), the row sums, the columns' x-y sums and their z running sums.
struct FusedLayout
{
  Index width;  // kTileX + 2 rx
  Index height; // kTileY + 2 ry

  VAO_HD Index loaded() const { return width * height; }
  VAO_HD Index rows() const { return height * kTileX; }
  VAO_HD Index elements() const { return 2 * loaded() + 2 * rows() + 4 * kTileColumns; }
};

VAO_HD FusedLayout fusedLayout(const RegionGeometry& g)
{
  return FusedLayout{ kTileX + 2 * g.radius[0], kTileY + 2 * g.radius[1] };
}

/// The sums' arrays, carved from a block's shared accumulators in FusedLayout's order.
template <class Acc>
struct SumArrays
{
  Acc *v1, *v2, *r1, *r2, *xy1, *xy2, *z1, *z2;

  VAO_HD SumArrays(const FusedLayout& layout, Acc* shared)
    : v1(shared)
    , v2(v1 + layout.loaded())
    , r1(v2 + layout.loaded())
    , r2(r1 + layout.rows())
    , xy1(r2 + layout.rows())
    , xy2(xy1 + kTileColumns)
    , z1(xy2 + kTileColumns)
    , z2(z1 + kTileColumns)
  {
  }
};

/// Sums of both channels over windows of k inputs for `count` outputs: inputs at stride
/// `step`, outputs at stride `outStep`, a running window moved by one addition and one
/// subtraction per output.
template <class Acc>
VAO_HD void windowSums(const Acc* in1, const Acc* in2, Index step, Index count, Index k, Acc* out1,
  Acc* out2, Index outStep)
{
  Acc s1 = 0, s2 = 0;
  for (Index i = 0; i < k; ++i)
  {
    s1 += in1[i * step];
    s2 += in2[i * step];
  }
  for (Index c = 0; c < count; ++c)
  {
    out1[c * outStep] = s1;
    out2[c * outStep] = s2;
    if (c + 1 < count)
    {
      s1 += in1[(c + k) * step] - in1[c * step];
      s2 += in2[(c + k) * step] - in2[c * step];
    }
  }
}

/// Bytes of the sums' part of a block's shared memory, rounded to 16 (the extrema follow).
template <class Acc>
VAO_HD Index fusedSumBytes(const RegionGeometry& g)
{
  return (fusedLayout(g).elements() * static_cast<Index>(sizeof(Acc)) + 15) / 16 * 16;
}

/// The fused pass over the region slices [sliceBegin, sliceEnd) (a z slab; the whole
/// region is one): the box sums of the two channels Source::load(block index, v1, v2)
/// gives (the moments, or Histogram CDF's indicators), each voxel's pair handed to
/// Sink::write(region index, block z, region x, region y, s1, s2), with the box's
/// minimum and maximum after them when Extrema is FusedExtrema (FusedExtrema.h).
template <class Source, class Sink, class AccT, class Extrema = NoExtrema>
struct FusedBoxSums
{
  using Acc = AccT;
  Source source;
  Sink sink;
  RegionGeometry g;
  Index sliceBegin;
  Index sliceEnd;
  Index segment; // slices a block walks: its first window costs 2 rz + 1 slices
  Extrema extrema;

  VAO_HD Index tilesX() const { return (g.rx + kTileX - 1) / kTileX; }
  VAO_HD Index tilesY() const { return (g.ry + kTileY - 1) / kTileY; }
  VAO_HD Index blocks() const
  {
    return tilesX() * tilesY() * segmentsOf(sliceEnd - sliceBegin, segment);
  }
  /// The sums' accumulators, then (16-byte aligned) the extrema's arrays.
  VAO_HD Index sumBytes() const { return fusedSumBytes<Acc>(g); }
  VAO_HD Index sharedBytes() const { return sumBytes() + extrema.bytes(g); }

  template <class Block>
  VAO_HD void run(const Block& block, Index blockIndex, Acc* shared) const
  {
    const SumArrays<Acc> a(fusedLayout(g), shared);
    const Index x0 = (blockIndex % tilesX()) * kTileX;
    const Index y0 = ((blockIndex / tilesX()) % tilesY()) * kTileY;
    const Index first = sliceBegin + (blockIndex / (tilesX() * tilesY())) * segment;
    const Index last = lower(first + segment, sliceEnd);
    const Index rz = g.radius[2];

    unsigned char* extremaShared = reinterpret_cast<unsigned char*>(shared) + sumBytes();
    block.each(kTileColumns,
      [&](Index c)
      {
        a.z1[c] = 0;
        a.z2[c] = 0;
      });
    if constexpr (Extrema::kEnabled)
      extrema.reset(block, g, extremaShared);
    const Index lo = greater(Index(0), g.oz + first - rz), hi = lower(g.sz - 1, g.oz + first + rz);
    for (Index j = lo; j <= hi; ++j)
    {
      this->addSlice(block, shared, x0, y0, j, true);
    }
    for (Index k = first; k < last; ++k)
    {
      const Index z = g.oz + k;
      block.each(kTileColumns,
        [&](Index c)
        {
          const Index x = x0 + c % kTileX, y = y0 + c / kTileX;
          if constexpr (Extrema::kEnabled)
          {
            double minimum, maximum; // every column's deques move on, inside the region or not
            extrema.window(g, extremaShared, c, z, minimum, maximum);
            if (x < g.rx && y < g.ry)
              sink.write((k * g.ry + y) * g.rx + x, z, x, y, a.z1[c], a.z2[c], minimum, maximum);
          }
          else if (x < g.rx && y < g.ry)
            sink.write((k * g.ry + y) * g.rx + x, z, x, y, a.z1[c], a.z2[c]);
        });
      if (k + 1 == last)
        break;
      if (z + rz + 1 <= g.sz - 1)
        this->addSlice(block, shared, x0, y0, z + rz + 1, true);
      if (z - rz >= 0)
        this->addSlice(block, shared, x0, y0, z - rz, false);
    }
  }

  /// Adds (or subtracts) block slice j's x-y box sums to the columns' z running sums.
  template <class Block>
  VAO_HD void addSlice(const Block& block, Acc* shared, Index x0, Index y0, Index j, bool add) const
  {
    const FusedLayout layout = fusedLayout(g);
    const SumArrays<Acc> a(layout, shared);
    unsigned char* extremaShared = reinterpret_cast<unsigned char*>(shared) + sumBytes();
    const Index rx = g.radius[0], ry = g.radius[1];
    // The tile and its halo; zero outside the block, which holds every voxel of the
    // volume a window of the region reaches. The extrema's copy of an entering slice is
    // loaded in the same phase.
    block.each(layout.loaded(),
      [&](Index i)
      {
        const Index bx = g.ox + x0 - rx + i % layout.width, by = g.oy + y0 - ry + i / layout.width;
        Acc m1 = 0, m2 = 0;
        if (bx >= 0 && bx < g.sx && by >= 0 && by < g.sy)
          source.load((j * g.sy + by) * g.sx + bx, m1, m2);
        a.v1[i] = m1;
        a.v2[i] = m2;
        if constexpr (Extrema::kEnabled)
        {
          if (add)
            extrema.load(g, extremaShared, i, bx, by, j);
        }
      });
    // Each loaded row's sums over the x windows of the tile's columns.
    block.each(layout.height,
      [&](Index row)
      {
        windowSums(a.v1 + row * layout.width, a.v2 + row * layout.width, 1, kTileX, 2 * rx + 1,
          a.r1 + row * kTileX, a.r2 + row * kTileX, 1);
      });
    // Each column's sums of those over the y windows.
    block.each(kTileX,
      [&](Index c) {
        windowSums(a.r1 + c, a.r2 + c, kTileX, kTileY, 2 * ry + 1, a.xy1 + c, a.xy2 + c, kTileX);
      });
    block.each(kTileColumns,
      [&](Index c)
      {
        a.z1[c] = add ? a.z1[c] + a.xy1[c] : a.z1[c] - a.xy1[c];
        a.z2[c] = add ? a.z2[c] + a.xy2[c] : a.z2[c] - a.xy2[c];
      });
    if constexpr (Extrema::kEnabled)
    {
      if (add) // a leaving slice leaves the deques by itself
        extrema.enter(block, g, extremaShared, j);
    }
  }
};

/// The fused pass of the moment estimators and statistics: the shifted moments of the
/// block, the estimator's writer; with the extrema (CDF Reconstruction, the statistics'
/// minimum and maximum) or without.
template <class T, class Acc, class Extrema = NoExtrema>
using FusedStatisticsKernel =
  FusedBoxSums<MomentSource<T, Acc, true>, StatisticsWriter<T, Acc>, Acc, Extrema>;

template <class T, class Acc>
FusedStatisticsKernel<T, Acc> fusedStatistics(
  const StatisticsWriter<T, Acc>& writer, Index sliceBegin, Index sliceEnd, Index segment)
{
  return { { writer.input, nullptr, writer.shift }, writer, writer.g, sliceBegin, sliceEnd, segment,
    {} };
}

template <class T, class Acc>
FusedStatisticsKernel<T, Acc, FusedExtrema<T>> fusedStatisticsWithExtrema(
  const StatisticsWriter<T, Acc>& writer, Index sliceBegin, Index sliceEnd, Index segment)
{
  return { { writer.input, nullptr, writer.shift }, writer, writer.g, sliceBegin, sliceEnd, segment,
    { writer.input } };
}

/// Whether the fused pass fits a block's shared memory (`sharedLimit` bytes) for sums in
/// Acc and, withExtrema, the extrema of T.
template <class Acc, class T>
bool fusedPassFits(const RegionGeometry& g, bool withExtrema, Index sharedLimit)
{
  return fusedSumBytes<Acc>(g) + (withExtrema ? FusedExtrema<T>{ nullptr }.bytes(g) : 0) <=
    sharedLimit;
}

} // namespace gpu
} // namespace vao
