#include "cpu/exact_reference/ExactReference.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
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

/// A voxel counts when double(v) <= q (docs/methods.md, Notation). Every value of a type of up to
/// 32 bits is a double, so that test holds exactly when v <= t, t the largest value of the type at
/// most q, and it runs in the type itself: 8 to 32 lanes a vector. 64-bit integers round
/// on the way to double, so they compare as doubles.
template <class T>
struct AtMost
{
  using Type =
    typename std::conditional<std::is_integral<T>::value && sizeof(T) == 8, double, T>::type;

  /// The largest Type at most q; false when none is (q NaN or below every value).
  static bool threshold(double q, Type& t)
  {
    using Limits = std::numeric_limits<Type>;
    if (std::isnan(q))
    {
      return false;
    }
    if constexpr (std::is_same<Type, double>::value)
    {
      t = static_cast<Type>(q);
    }
    else if constexpr (std::is_floating_point<Type>::value)
    {
      // Beyond the largest finite float only the infinity on q's side can count.
      if (q > static_cast<double>(Limits::max()) || q < static_cast<double>(Limits::lowest()))
      {
        t = q == Limits::infinity() ? Limits::infinity()
                                    : (q > 0 ? Limits::max() : -Limits::infinity());
      }
      else
      {
        t = static_cast<Type>(q);
        if (static_cast<double>(t) > q)
        {
          t = std::nextafter(t, -Limits::infinity());
        }
      }
    }
    else
    {
      if (q < static_cast<double>(Limits::lowest()))
      {
        return false;
      }
      t =
        q >= static_cast<double>(Limits::max()) ? Limits::max() : static_cast<Type>(std::floor(q));
    }
    return true;
  }
};

/// part[i] += 1 where row[i + dx] <= t[i], for i in [from, to): the neighbours at offset dx
/// of a run of voxels, each against its own threshold.
template <class T, class C>
void countAtOffset(const T* row, const C* t, std::int64_t from, std::int64_t to, std::int64_t dx,
  std::uint32_t* part)
{
  for (std::int64_t i = from; i < to; ++i)
  {
    part[i] += static_cast<C>(row[i + dx]) <= t[i] ? 1u : 0u;
  }
}

/// One output row (y, z) of the region, counted offset by offset across the row: each
/// pass compares a run of neighbours with the run of thresholds, which vectorises whatever
/// the radius, where a voxel's own rows of 2 R + 1 values would not.
template <class T>
struct ExactRow
{
  using C = typename AtMost<T>::Type;
  std::vector<C> thresholds;
  std::vector<std::uint8_t> counted;
  std::vector<std::uint32_t> part;
  std::vector<std::int64_t> below, total;
  std::vector<T> gathered;

  void run(const TypedVolume<T>& volume, const Region& region, const AmbientOcclusionParameters& p,
    const std::vector<std::int64_t>& halfWidths, std::int64_t y, std::int64_t z,
    const double* query, float* out)
  {
    const Radius& r = p.radius;
    const Index3& n = volume.dims;
    const std::int64_t x0 = region.begin[0], nx = region.size[0];
    const std::int64_t first =
      ((z - region.begin[2]) * region.size[1] + (y - region.begin[1])) * nx;
    thresholds.resize(nx);
    counted.resize(nx);
    part.resize(nx);
    below.assign(nx, 0);
    total.assign(nx, 0);
    for (std::int64_t i = 0; i < nx; ++i)
    {
      const double q = query
        ? query[first + i]
        : (p.queryMode == QueryMode::IsoValue ? p.isoValue
                                              : static_cast<double>(volume.value(x0 + i, y, z)));
      counted[i] = AtMost<T>::threshold(q, thresholds[i]) ? 1 : 0;
    }
    for (std::int64_t dz = -r.z; dz <= r.z; ++dz)
    {
      for (std::int64_t dy = -r.y; dy <= r.y; ++dy)
      {
        const std::int64_t hw = halfWidths[(dz + r.z) * (2 * r.y + 1) + (dy + r.y)];
        if (hw < 0 || z + dz < 0 || z + dz >= n[2] || y + dy < 0 || y + dy >= n[1])
        {
          continue;
        }
        const T* row = volume.row(y + dy, z + dz);
        if (volume.stride != 1)
        {
          gathered.resize(n[0]);
          for (std::int64_t x = 0; x < n[0]; ++x)
          {
            gathered[x] = row[x * volume.stride];
          }
          row = gathered.data();
        }
        std::fill(part.begin(), part.end(), 0u);
        // Offsets beyond the volume's x range have no neighbours to count.
        for (std::int64_t dx = std::max(-hw, -x0 - nx + 1); dx <= std::min(hw, n[0] - 1 - x0); ++dx)
        {
          countAtOffset(row + x0, thresholds.data(), std::max<std::int64_t>(0, -x0 - dx),
            std::min(nx, n[0] - x0 - dx), dx, part.data());
        }
        for (std::int64_t i = 0; i < nx; ++i)
        {
          const std::int64_t x = x0 + i;
          below[i] += part[i];
          total[i] += std::min(n[0] - 1, x + hw) - std::max<std::int64_t>(0, x - hw) + 1;
        }
      }
    }
    for (std::int64_t i = 0; i < nx; ++i)
    {
      const double counts = counted[i] ? static_cast<double>(below[i]) : 0.0;
      out[first + i] = static_cast<float>(counts / static_cast<double>(total[i]));
    }
  }
};

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
  const AmbientOcclusionParameters& p, const double* query, float* openness,
  const Execution& execution)
{
  const std::vector<std::int64_t> halfWidths =
    neighbourhoodRowHalfWidths(p.radius, p.method == Method::ExactSphere);
  const bool finished = dispatchScalarType(view.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const TypedVolume<T> volume(view);
      // One slice per chunk: slices cost the same, and progress moves often.
      return parallelFor(region.size[2], static_cast<int>(region.size[2]), execution.threads,
        execution,
        [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
        {
          ExactRow<T> rows;
          for (std::int64_t k = begin; k < end && !progress.stopped(); ++k)
          {
            for (std::int64_t y = region.begin[1]; y < region.begin[1] + region.size[1]; ++y)
            {
              rows.run(volume, region, p, halfWidths, y, region.begin[2] + k, query, openness);
            }
            progress.advance();
          }
        });
    });
  return finished ? Status::success() : Status::cancelled();
}

} // namespace detail
} // namespace vao
