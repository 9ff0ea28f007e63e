// computeBoxStatistics: the separable statistics written out per voxel (for tests,
// benchmarks and users who want the fields themselves).
#include "BoxEngine.h"

#include "vao/Validation.h"

namespace vao
{

Status computeBoxStatistics(const VolumeView& view, const Region& region, const Radius& radius,
  const BoxStatisticsOutput& output, const Execution& execution)
{
  Status status = validate(view, region, radius);
  if (!status.ok)
  {
    return status;
  }
  const detail::BoxGeometry geometry(view.dims, region, radius);
  const bool withExtrema = output.minimum || output.maximum;
  return catchOutOfMemory("the working buffers of the box statistics", [&] {
  return detail::dispatchScalarType(view.type, [&](auto tag) -> Status {
    const detail::TypedVolume<decltype(tag)> volume(view);
    // Only the shift matters here: the statistics are written as they are.
    const detail::MomentScale scale{ detail::momentScale(volume, 0.0, 0.0).shift, 0.0 };
    const bool ok = detail::forEachNeighbourhood(volume, geometry, scale, withExtrema, execution,
      [&](const detail::VoxelNeighbourhood& voxel) {
        const std::int64_t k = voxel.index;
        if (output.count)
          output.count[k] = static_cast<double>(voxel.count);
        if (output.mean)
          output.mean[k] = voxel.stats.mean;
        if (output.variance)
          output.variance[k] = voxel.stats.variance;
        if (output.minimum)
          output.minimum[k] = voxel.stats.minimum;
        if (output.maximum)
          output.maximum[k] = voxel.stats.maximum;
      });
    return ok ? Status::success() : Status::cancelled();
  });
  });
}

} // namespace vao
