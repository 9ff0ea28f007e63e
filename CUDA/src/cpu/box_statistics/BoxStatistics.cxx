// computeBoxStatistics: the separable statistics written out per voxel (for tests,
// benchmarks and users who want the fields themselves).
#include "cpu/box_statistics/BoxEngine.h"

#include "vao/Validation.h"

#include <algorithm>

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
  return catchOutOfMemory("the working buffers of the box statistics",
    [&]
    {
      return detail::dispatchScalarType(view.type,
        [&](auto tag) -> Status
        {
          const detail::TypedVolume<decltype(tag)> volume(view);
          // Only the shift matters here: the statistics are written as they are.
          const detail::MomentScale scale{ detail::momentScale(volume, 0.0, 0.0).shift, 0.0 };
          const bool ok = detail::forEachNeighbourhoodRow(volume, geometry, scale,
            detail::RowContents{ withExtrema, true, false }, execution,
            [&](const detail::NeighbourhoodRow& row)
            {
              const auto put = [&](double* field, const double* values)
              {
                if (field)
                  std::copy(values, values + row.size, field + row.index);
              };
              put(output.count, row.count);
              put(output.mean, row.mean);
              put(output.variance, row.variance);
              put(output.minimum, row.minimum);
              put(output.maximum, row.maximum);
            });
          return ok ? Status::success() : Status::cancelled();
        });
    });
}

} // namespace vao
