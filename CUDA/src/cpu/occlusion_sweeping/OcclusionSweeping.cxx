// Occlusion sweeping (Singh, Yuksel & House 2009; docs/methods.md, Singh et al.):
// fast sweeping of the signed distance with the octant visibility of Eq. 6 carried along
// in the same sweeps, then the per-voxel combination into AmbientOcclusion (Eq. 4/5).
// This file is the whole-volume driver; the stages are in SweepingCore.h.
//
// D is a signed float field: the sign is fixed at initialisation by inside(v), and the
// sweeps only lower |D|.
#include "vao/OcclusionSweeping.h"

#include "cpu/common/Parallel.h"
#include "cpu/occlusion_sweeping/SweepingCore.h"
#include "vao/Validation.h"

#include <algorithm>
#include <new>
#include <vector>

namespace vao
{
namespace
{

using namespace detail::sweeping;

/// What the request needs: the octants whose V is computed, and whether V is kept per
/// octant (OctantVisibility, or the geometry term that needs the final N).
VisibilityStore planVisibility(
  const Grid& grid, const SweepParameters& p, const SweepOutput& out, int sweepThreads)
{
  VisibilityStore vis;
  int computedCount = 0;
  for (int s = 0; s < 8; ++s)
  {
    vis.computed[s] = out.octantVisibility || (out.ambientOcclusion && p.octantMask[s]);
    computedCount += vis.computed[s];
  }
  if (out.octantVisibility || (out.ambientOcclusion && p.useGeometryTerm))
  {
    vis.keep(grid, out.octantVisibility);
  }
  else if (computedCount > 0)
  {
    vis.ringPlanes = ringPlanesFor(sweepThreads, grid.nz);
    vis.ring.resize(static_cast<std::size_t>(vis.ringPlanes * grid.plane));
    vis.sum = out.ambientOcclusion;
  }
  return vis;
}

/// D of the whole volume from sweep units to world units, in place.
void distanceToWorld(float* distance, std::int64_t count, double unit, int threads)
{
  const float scale = static_cast<float>(unit);
  detail::parallelFor(count, 4 * threads, threads,
    [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t i = begin; i < end; ++i)
        distance[i] *= scale;
    });
}

Status occlusionSweeping(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& parameters, const SweepOutput& out, const Execution& execution,
  SweepReport& report)
{
  const double unit = sweepUnit(spacing);
  SweepParameters p = parameters;
  p.tolerance /= unit;
  const SweepLayout layout = SweepLayout::wholeVolume(volume.dims, inSweepUnits(spacing));
  const Grid& grid = layout.storage;
  const int threads = detail::resolveThreadCount(execution.threads);
  StorageArray<float> ownDistance; // initialiseDistance writes every voxel
  float* distance = out.signedDistance;
  if (!distance)
  {
    ownDistance.resize(static_cast<std::size_t>(grid.count));
    distance = ownDistance.data();
  }
  const int sweepThreads = static_cast<int>(std::min<std::int64_t>(threads, grid.nz));
  VisibilityStore vis = planVisibility(grid, p, out, sweepThreads);
  double maskCount = 0.0;
  for (bool m : p.octantMask)
    maskCount += m;

  const std::int64_t fixedCount =
    initialiseDistance(volume, { 0, 0, 0 }, layout, p, distance, threads);
  FixedMask fixed;
  fixed.build(distance, grid.count, threads);
  report.surfaceFound = fixedCount > 0;
  report.passes = 0;
  report.lastChange = 0.0;
  if (report.surfaceFound)
  {
    const Status status = runPasses(layout, p, distance, fixed, vis, sweepThreads,
      detail::stageExecution(execution, 0.0, 0.95), report);
    report.lastChange *= unit;
    if (!status.ok)
    {
      return status;
    }
  }
  else
  {
    fillWithoutSurface(layout, distance[0] < 0.0f, distance, vis, maskCount);
  }
  const Status status = combine(layout, p, out, distance, vis, maskCount, threads,
    detail::stageExecution(execution, 0.95, 1.0));
  if (!status.ok)
  {
    return status;
  }
  if (out.signedDistance && unit != 1.0)
  {
    distanceToWorld(out.signedDistance, grid.count, unit, threads);
  }
  if (execution.progress)
  {
    execution.progress(1.0); // the last chunk may have finished on another thread
  }
  return Status::success();
}

} // namespace
Status computeOcclusionSweeping(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& parameters, const SweepOutput& output, const Execution& execution,
  SweepReport* report)
{
  const Status status = validateSweep(volume, spacing, parameters, output);
  if (!status.ok)
  {
    return status;
  }
  SweepReport local;
  return catchOutOfMemory("the sweeping buffers (signed distance, fixed voxels, octant visibility)",
    [&]
    {
      return occlusionSweeping(
        volume, spacing, parameters, output, execution, report ? *report : local);
    });
}

} // namespace vao
