#include "ExactReference.h"

#include "Parallel.h"
#include "VolumeAccess.h"

#include <cmath>
#include <vector>

namespace vao
{
namespace detail
{
namespace
{

/// Half-width along x of the neighbourhood's row at offset (dy, dz), or -1 when the row is
/// outside it, tested in integers so that voxels exactly on the surface are in.
std::int64_t rowHalfWidth(const Radius& r, std::int64_t dy, std::int64_t dz, bool sphere)
{
  if (!sphere)
  {
    return r.x;
  }
  if ((r.y == 0 && dy != 0) || (r.z == 0 && dz != 0))
  {
    return -1;
  }
  // Multiply through by the product of the non-zero squared radii.
  const std::int64_t ax = std::max(r.x, 1), ay = std::max(r.y, 1), az = std::max(r.z, 1);
  const std::int64_t rx2 = ax * ax, ry2 = ay * ay, rz2 = az * az;
  const std::int64_t budget = rx2 * ry2 * rz2 - dy * dy * rx2 * rz2 - dz * dz * rx2 * ry2;
  if (budget < 0)
  {
    return -1;
  }
  if (r.x == 0)
  {
    return 0;
  }
  // Largest dx with dx^2 * ry2 * rz2 <= budget.
  const std::int64_t scale = ry2 * rz2;
  auto dx = static_cast<std::int64_t>(std::sqrt(static_cast<double>(budget) / scale));
  while (dx > 0 && dx * dx * scale > budget)
  {
    --dx;
  }
  while ((dx + 1) * (dx + 1) * scale <= budget)
  {
    ++dx;
  }
  return dx;
}

template <class T>
void exactSlice(const TypedVolume<T>& volume, const Region& region,
  const AmbientOcclusionParameters& p, const std::vector<std::int64_t>& halfWidths,
  std::int64_t z, const double* query, float* out)
{
  const Radius& r = p.radius;
  const Index3& n = volume.dims;
  const bool iso = p.queryMode == QueryMode::IsoValue;
  for (std::int64_t y = region.begin[1]; y < region.begin[1] + region.size[1]; ++y)
  {
    for (std::int64_t x = region.begin[0]; x < region.begin[0] + region.size[0]; ++x)
    {
      const std::int64_t k = ((z - region.begin[2]) * region.size[1] + (y - region.begin[1])) *
          region.size[0] + (x - region.begin[0]);
      const double q = query ? query[k] : (iso ? p.isoValue : static_cast<double>(volume.value(x, y, z)));
      std::int64_t below = 0, total = 0;
      for (std::int64_t dz = -r.z; dz <= r.z; ++dz)
      {
        if (z + dz < 0 || z + dz >= n[2])
        {
          continue;
        }
        for (std::int64_t dy = -r.y; dy <= r.y; ++dy)
        {
          const std::int64_t hw = halfWidths[(dz + r.z) * (2 * r.y + 1) + (dy + r.y)];
          if (hw < 0 || y + dy < 0 || y + dy >= n[1])
          {
            continue;
          }
          const std::int64_t lo = std::max<std::int64_t>(0, x - hw);
          const std::int64_t hi = std::min<std::int64_t>(n[0] - 1, x + hw);
          const T* row = volume.row(y + dy, z + dz);
          for (std::int64_t i = lo; i <= hi; ++i)
          {
            below += static_cast<double>(row[i * volume.stride]) <= q ? 1 : 0;
          }
          total += hi - lo + 1;
        }
      }
      out[k] = static_cast<float>(static_cast<double>(below) / static_cast<double>(total));
    }
  }
}

} // namespace

std::vector<std::int64_t> neighbourhoodRowHalfWidths(const Radius& r, bool sphere)
{
  std::vector<std::int64_t> halfWidths;
  for (std::int64_t dz = -r.z; dz <= r.z; ++dz)
  {
    for (std::int64_t dy = -r.y; dy <= r.y; ++dy)
    {
      halfWidths.push_back(rowHalfWidth(r, dy, dz, sphere));
    }
  }
  return halfWidths;
}

Status computeExactOpenness(const VolumeView& view, const Region& region,
  const AmbientOcclusionParameters& p, const double* query, float* openness, const Execution& execution)
{
  const std::vector<std::int64_t> halfWidths = neighbourhoodRowHalfWidths(p.radius, p.method == Method::ExactSphere);
  const bool finished = dispatchScalarType(view.type, [&](auto tag) {
    using T = decltype(tag);
    const TypedVolume<T> volume(view);
    // One slice per chunk: slices cost the same, and progress moves often.
    return parallelFor(region.size[2], static_cast<int>(region.size[2]), execution.threads, execution,
      [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
        for (std::int64_t k = begin; k < end && !progress.stopped(); ++k)
        {
          exactSlice(volume, region, p, halfWidths, region.begin[2] + k, query, openness);
          progress.advance();
        }
      });
  });
  return finished ? Status::success() : Status::cancelled();
}

} // namespace detail
} // namespace vao
