// Exact Box and Exact Sphere on the device (the references of Ruiz et al., docs/methods.md section
// 1-2): one thread per region voxel counts the values at or below its query over the rows of its
// clipped box or ellipsoid, as ExactReference.cxx does on the CPU, with the same rows
// (neighbourhoodRowHalfWidths) and the same division. Written once for the CUDA executor
// and the host emulation of the tests, like Pipeline.h; no CUDA runtime calls here.
//
// O(R^3) per voxel, as the definition is. Adjacent threads are adjacent voxels along x:
// they read the same rows shifted by one value, so the loads coalesce and the caches
// serve the (2R + 1)^3 reads of each value. The region goes in slabs of slices, so that
// one launch stays short (progress and Abort between them, no display watchdog).
#pragma once

#include "cuda/common/Pipeline.h"

#include <cstdint>
#include <vector>

namespace vao
{
namespace gpu
{

template <class T>
struct ExactCount
{
  const T* block; // the uploaded block (RegionGeometry)
  RegionGeometry g;
  const Index* halfWidths; // per neighbourhood row (dz, dy): x half-width, -1 outside
  bool iso;                // the query: the iso value, else the voxel's own value
  double isoValue;
  Index zBegin, zCount; // the region's slices of this launch
  float* openness;      // region-sized, x fastest

  VAO_HD Index threads() const { return g.rx * g.ry * zCount; }

  VAO_HD void operator()(Index t) const
  {
    const Index x = t % g.rx, y = (t / g.rx) % g.ry, z = zBegin + t / (g.rx * g.ry);
    const Index cx = g.ox + x, cy = g.oy + y, cz = g.oz + z;
    const double q = iso ? isoValue : static_cast<double>(block[(cz * g.sy + cy) * g.sx + cx]);
    const Index ry = g.radius[1], rz = g.radius[2];
    long long below = 0, total = 0;
    for (Index dz = -rz; dz <= rz; ++dz)
    {
      const Index zz = cz + dz;
      if (zz < 0 || zz >= g.sz)
        continue;
      for (Index dy = -ry; dy <= ry; ++dy)
      {
        const Index yy = cy + dy;
        const Index hw = halfWidths[(dz + rz) * (2 * ry + 1) + (dy + ry)];
        if (hw < 0 || yy < 0 || yy >= g.sy)
          continue;
        const Index lo = greater<Index>(0, cx - hw), hi = lower<Index>(g.sx - 1, cx + hw);
        const T* row = block + (zz * g.sy + yy) * g.sx;
        for (Index i = lo; i <= hi; ++i)
          below += static_cast<double>(row[i]) <= q ? 1 : 0;
        total += hi - lo + 1;
      }
    }
    openness[(z * g.ry + y) * g.rx + x] =
      static_cast<float>(static_cast<double>(below) / static_cast<double>(total));
  }
};

/// The exact openness of every region voxel into `openness`, over the neighbourhood rows
/// `rows` (neighbourhoodRowHalfWidths, on the host), in launches of whole slices and about
/// `visitsPerLaunch` value visits; progress moves from `from` to `to` between them.
template <class T, class Executor>
void runExactPasses(Executor& ex, const T* block, const RegionGeometry& g,
  const std::vector<std::int64_t>& rows, bool iso, double isoValue, float* openness, double from,
  double to, double visitsPerLaunch = 1 << 30)
{
  const std::vector<Index> widths(rows.begin(), rows.end());
  Index neighbourhood = 0; // voxels of an unclipped neighbourhood
  for (const Index w : widths)
    neighbourhood += w >= 0 ? 2 * w + 1 : 0;
  const auto halfWidths = ex.upload(widths.data(), static_cast<Index>(widths.size()));
  const double perSlice =
    static_cast<double>(g.rx * g.ry) * static_cast<double>(greater<Index>(neighbourhood, 1));
  const Index depth =
    greater<Index>(1, lower<Index>(g.rz, static_cast<Index>(visitsPerLaunch / perSlice)));
  for (Index z = 0; z < g.rz; z += depth)
  {
    const ExactCount<T> kernel{ block, g, halfWidths.get(), iso, isoValue, z,
      lower<Index>(depth, g.rz - z), openness };
    // Bytes: the slab's rows from memory once, the openness written once.
    const double bytes = static_cast<double>(kernel.threads()) * (sizeof(float) + sizeof(T));
    ex.launch(kernel, "exact count", bytes);
    ex.synchronize(); // progress and Abort follow the device, not the queue
    ex.progress(
      from + (to - from) * static_cast<double>(z + kernel.zCount) / static_cast<double>(g.rz));
  }
}

} // namespace gpu
} // namespace vao
