// The box minimum and maximum inside the fused pass (FusedStatistics.h), for CDF
// Reconstruction and the statistics: each slice that enters a block's columns gets its
// x-y window extrema in shared memory, by van Herk / Gil-Werman along the rows and then
// the columns (a suffix array per block of 2 r + 1, a running prefix: O(1) per voxel
// whatever the radius); along z each column keeps a monotonic deque of the slices in its
// window (the minimum's and the maximum's), so a slice that leaves needs no work and each
// slice is pushed and popped at most once. The deques hold 2 rz + 2 slices a column, which
// is what limits the radius a block's shared memory allows.
#pragma once

#include "cuda/common/FusedTile.h"
#include "cuda/common/Pipeline.h"

namespace vao
{
namespace gpu
{

/// The fused pass without extrema.
struct NoExtrema
{
  static constexpr bool kEnabled = false;
  VAO_HD Index bytes(const RegionGeometry&) const { return 0; }
};

/// The extrema of the uploaded block's values.
template <class T>
struct FusedExtrema
{
  static constexpr bool kEnabled = true;
  const T* input; // the uploaded block

  /// Where each array lives in the block's shared bytes (T arrays first, then ints).
  struct Layout
  {
    Index width, height, depth; // the tile with its halo; deque slots per column
    VAO_HD Index values() const { return width * height; }
    VAO_HD Index tValues() const
    {
      return 3 * values() + 4 * height * kTileX + 2 * kTileColumns + 2 * depth * kTileColumns;
    }
    VAO_HD Index ints() const { return 2 * depth * kTileColumns + 4 * kTileColumns; }
  };

  VAO_HD static Layout layout(const RegionGeometry& g)
  {
    return Layout{ kTileX + 2 * g.radius[0], kTileY + 2 * g.radius[1], 2 * g.radius[2] + 2 };
  }
  VAO_HD Index bytes(const RegionGeometry& g) const
  {
    const Layout l = layout(g);
    return (l.tValues() * static_cast<Index>(sizeof(T)) + 15) / 16 * 16 + l.ints() * 4;
  }

  /// The arrays, carved from `shared` (16-byte aligned).
  struct Arrays
  {
    T *value, *rowSufMin, *rowSufMax, *rowMin, *rowMax, *colSufMin, *colSufMax, *xyMin, *xyMax,
      *dqMin, *dqMax;
    int *dqMinSlice, *dqMaxSlice, *minHead, *minCount, *maxHead, *maxCount;
  };
  VAO_HD static Arrays arrays(const RegionGeometry& g, unsigned char* shared)
  {
    const Layout l = layout(g);
    Arrays a;
    T* t = reinterpret_cast<T*>(shared);
    a.value = t;
    a.rowSufMin = a.value + l.values();
    a.rowSufMax = a.rowSufMin + l.values();
    a.rowMin = a.rowSufMax + l.values();
    a.rowMax = a.rowMin + l.height * kTileX;
    a.colSufMin = a.rowMax + l.height * kTileX;
    a.colSufMax = a.colSufMin + l.height * kTileX;
    a.xyMin = a.colSufMax + l.height * kTileX;
    a.xyMax = a.xyMin + kTileColumns;
    a.dqMin = a.xyMax + kTileColumns;
    a.dqMax = a.dqMin + l.depth * kTileColumns;
    int* n =
      reinterpret_cast<int*>(shared + (l.tValues() * static_cast<Index>(sizeof(T)) + 15) / 16 * 16);
    a.dqMinSlice = n;
    a.dqMaxSlice = n + l.depth * kTileColumns;
    a.minHead = a.dqMaxSlice + l.depth * kTileColumns;
    a.minCount = a.minHead + kTileColumns;
    a.maxHead = a.minCount + kTileColumns;
    a.maxCount = a.maxHead + kTileColumns;
    return a;
  }

  /// Window minima of inMin and maxima of inMax for `count` outputs, window k = 2 r + 1,
  /// over count + k - 1 inputs at stride `step`: van Herk with the blocks' suffixes in
  /// suf*, a running prefix.
  VAO_HD static void windows(const T* inMin, const T* inMax, Index step, Index count, Index k,
    T* sufMin, T* sufMax, T* outMin, T* outMax, Index outStep)
  {
    const Index n = count + k - 1;
    for (Index p = n - 1; p >= 0; --p)
    {
      const bool blockEnd = p == n - 1 || (p + 1) % k == 0;
      sufMin[p * step] =
        blockEnd ? inMin[p * step] : lower(inMin[p * step], sufMin[(p + 1) * step]);
      sufMax[p * step] =
        blockEnd ? inMax[p * step] : greater(inMax[p * step], sufMax[(p + 1) * step]);
    }
    T preMin = inMin[0], preMax = inMax[0];
    for (Index p = 0; p < n; ++p)
    {
      preMin = p % k == 0 ? inMin[p * step] : lower(preMin, inMin[p * step]);
      preMax = p % k == 0 ? inMax[p * step] : greater(preMax, inMax[p * step]);
      const Index c = p - k + 1; // the output whose window ends at p
      if (c >= 0)
      {
        outMin[c * outStep] = lower(sufMin[c * step], preMin);
        outMax[c * outStep] = greater(sufMax[c * step], preMax);
      }
    }
  }

  template <class Block>
  VAO_HD void reset(const Block& block, const RegionGeometry& g, unsigned char* shared) const
  {
    const Arrays a = arrays(g, shared);
    block.each(kTileColumns,
      [&](Index c) { a.minHead[c] = a.minCount[c] = a.maxHead[c] = a.maxCount[c] = 0; });
  }

  /// Item i of the tile with its halo at block (bx, by) of slice j, into the loaded
  /// values (in the sums' load phase). Outside the block no voxel exists: the edge value
  /// stands in, which no window of a region voxel changes (its clipped window holds that
  /// voxel already).
  VAO_HD void load(
    const RegionGeometry& g, unsigned char* shared, Index i, Index bx, Index by, Index j) const
  {
    const Index x = lower(greater(bx, Index(0)), g.sx - 1),
                y = lower(greater(by, Index(0)), g.sy - 1);
    arrays(g, shared).value[i] = input[(j * g.sy + y) * g.sx + x];
  }

  /// Slice j, loaded, enters the columns' windows.
  template <class Block>
  VAO_HD void enter(
    const Block& block, const RegionGeometry& g, unsigned char* shared, Index j) const
  {
    const Layout l = layout(g);
    const Arrays a = arrays(g, shared);
    const Index rx = g.radius[0], ry = g.radius[1];
    block.each(l.height,
      [&](Index row)
      {
        const T* values = a.value + row * l.width;
        windows(values, values, 1, kTileX, 2 * rx + 1, a.rowSufMin + row * l.width,
          a.rowSufMax + row * l.width, a.rowMin + row * kTileX, a.rowMax + row * kTileX, 1);
      });
    block.each(kTileX,
      [&](Index c)
      {
        windows(a.rowMin + c, a.rowMax + c, kTileX, kTileY, 2 * ry + 1, a.colSufMin + c,
          a.colSufMax + c, a.xyMin + c, a.xyMax + c, kTileX);
      });
    block.each(kTileColumns,
      [&](Index c)
      {
        push(a.dqMin + c * l.depth, a.dqMinSlice + c * l.depth, a.minHead[c], a.minCount[c],
          l.depth, j, a.xyMin[c], true);
        push(a.dqMax + c * l.depth, a.dqMaxSlice + c * l.depth, a.maxHead[c], a.maxCount[c],
          l.depth, j, a.xyMax[c], false);
      });
  }

  /// Column c's extrema over block slices [z - rz, z + rz] (all entered): the deques'
  /// fronts once the slices before the window are gone.
  VAO_HD void window(const RegionGeometry& g, unsigned char* shared, Index c, Index z,
    double& minimum, double& maximum) const
  {
    const Layout l = layout(g);
    const Arrays a = arrays(g, shared);
    const Index first = z - g.radius[2];
    minimum = static_cast<double>(front(a.dqMin + c * l.depth, a.dqMinSlice + c * l.depth,
      a.minHead[c], a.minCount[c], l.depth, first));
    maximum = static_cast<double>(front(a.dqMax + c * l.depth, a.dqMaxSlice + c * l.depth,
      a.maxHead[c], a.maxCount[c], l.depth, first));
  }

private:
  /// Pushes (slice, v) at the back, dropping the entries it makes useless (not below it
  /// for the minimum, not above it for the maximum).
  VAO_HD static void push(
    T* value, int* slice, int& head, int& count, Index depth, Index j, T v, bool isMin)
  {
    while (count > 0)
    {
      const T back = value[(head + count - 1) % depth];
      if (isMin ? back < v : v < back)
        break;
      --count;
    }
    value[(head + count) % depth] = v;
    slice[(head + count) % depth] = static_cast<int>(j);
    ++count;
  }
  VAO_HD static T front(
    const T* value, const int* slice, int& head, int& count, Index depth, Index first)
  {
    while (slice[head] < first)
    {
      head = static_cast<int>((head + 1) % depth);
      --count;
    }
    return value[head];
  }
};

} // namespace gpu
} // namespace vao
