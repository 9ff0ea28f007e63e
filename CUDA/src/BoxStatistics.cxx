// computeBoxStatistics: the separable statistics written out per voxel (for tests,
// benchmarks and users who want the fields themselves).
#include "BoxEngine.h"

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
  const bool extrema = output.minimum || output.maximum;
  return detail::dispatchScalarType(view.type, [&](auto tag) -> Status {
    using T = decltype(tag);
    const detail::TypedVolume<T> volume(view);
    detail::BoxExtrema<T> boxExtrema;
    const double split = extrema ? 0.5 : 0.0;
    if (extrema &&
      !detail::computeBoxExtrema(volume, geometry, detail::stageExecution(execution, 0.0, split), boxExtrema))
    {
      return Status::cancelled();
    }
    const auto countX = geometry.windowCounts(0);
    const auto countY = geometry.windowCounts(1);
    const std::int64_t nx = region.size[0], ny = region.size[1];
    const bool ok = detail::streamMoments(volume, geometry,
      detail::stageExecution(execution, split, 1.0), [&](const detail::MomentSlice<T>& slice) {
        const std::int64_t base = (slice.z - region.begin[2]) * nx * ny;
        for (std::int64_t j = 0; j < ny; ++j)
        {
          for (std::int64_t i = 0; i < nx; ++i)
          {
            const std::int64_t p = j * nx + i;
            const std::int64_t k = base + p;
            const std::int64_t count = countX[i] * countY[j] * slice.countZ;
            double mean, variance;
            detail::momentsToMeanVariance(slice.sum[p], slice.sumSquares[p], count, slice.shift, mean, variance);
            if (output.count)
            {
              output.count[k] = static_cast<double>(count);
            }
            if (output.mean)
            {
              output.mean[k] = mean;
            }
            if (output.variance)
            {
              output.variance[k] = variance;
            }
            if (output.minimum)
            {
              output.minimum[k] = static_cast<double>(boxExtrema.minimum[k]);
            }
            if (output.maximum)
            {
              output.maximum[k] = static_cast<double>(boxExtrema.maximum[k]);
            }
          }
        }
      });
    return ok ? Status::success() : Status::cancelled();
  });
}

} // namespace vao
