// The argument checks of every entry point (vao/Validation.h), and the parallel scan for
// non-finite values.
#include "vao/Validation.h"

#include "Parallel.h"
#include "VolumeAccess.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <sstream>

namespace vao
{

Status Status::nonFinite(std::int64_t count, std::int64_t first)
{
  std::ostringstream why;
  why << "the volume has " << count << " non-finite value" << (count == 1 ? "" : "s")
      << " (NaN or infinity), the first at voxel index " << first;
  Status status = failure(why.str());
  status.nonFiniteCount = count;
  status.firstNonFinite = first;
  return status;
}

Status checkVolume(const VolumeView& volume, std::int64_t minimumPerAxis, const char* method)
{
  std::ostringstream why;
  const Index3& d = volume.dims;
  if (!volume.data || d[0] <= 0 || d[1] <= 0 || d[2] <= 0)
  {
    why << "the volume is empty (" << d[0] << " x " << d[1] << " x " << d[2] << " voxels)";
  }
  else if (volume.voxelStride < 1)
  {
    why << "the voxel stride must be at least 1 (got " << volume.voxelStride << ")";
  }
  else if (d[0] < minimumPerAxis || d[1] < minimumPerAxis || d[2] < minimumPerAxis)
  {
    why << (method ? method : "the method") << " needs a 3-D volume with at least " << minimumPerAxis
        << " voxels per axis (got " << d[0] << " x " << d[1] << " x " << d[2] << ")";
  }
  const std::string message = why.str();
  return message.empty() ? Status::success() : Status::failure(message);
}

Status checkRegion(const VolumeView& volume, const Region& region)
{
  for (int a = 0; a < 3; ++a)
  {
    if (region.size[a] <= 0 || region.begin[a] < 0 || region.begin[a] + region.size[a] > volume.dims[a])
    {
      std::ostringstream why;
      why << "the output region [" << region.begin[a] << ", " << region.begin[a] + region.size[a]
          << ") of axis " << a << " is empty or outside the volume's " << volume.dims[a] << " voxels";
      return Status::failure(why.str());
    }
  }
  return Status::success();
}

Status checkRadius(const Radius& radius)
{
  if (radius.x >= 0 && radius.y >= 0 && radius.z >= 0)
  {
    return Status::success();
  }
  std::ostringstream why;
  why << "the radius must not be negative (got " << radius.x << ", " << radius.y << ", " << radius.z
      << " voxels)";
  return Status::failure(why.str());
}

Status checkSpacing(const std::array<double, 3>& spacing, const char* what)
{
  for (double h : spacing)
  {
    if (!std::isfinite(h) || !(h > 0.0))
    {
      std::ostringstream why;
      why << what << " must be finite and positive (got " << spacing[0] << ", " << spacing[1] << ", "
          << spacing[2] << ")";
      return Status::failure(why.str());
    }
  }
  return Status::success();
}

Status checkFinitePoint(const std::array<double, 3>& point, const char* what)
{
  if (std::isfinite(point[0]) && std::isfinite(point[1]) && std::isfinite(point[2]))
  {
    return Status::success();
  }
  std::ostringstream why;
  why << what << " must be finite (got " << point[0] << ", " << point[1] << ", " << point[2] << ")";
  return Status::failure(why.str());
}

Status checkFiniteParameter(double value, const char* what)
{
  if (std::isfinite(value))
  {
    return Status::success();
  }
  std::ostringstream why;
  why << what << " must be a finite number (got " << value << ")";
  return Status::failure(why.str());
}

Status validate(const VolumeView& volume, const Region& region, const Radius& radius)
{
  Status status = checkVolume(volume);
  if (status.ok)
    status = checkRadius(radius);
  if (status.ok)
    status = checkRegion(volume, region);
  return status;
}

std::int64_t countNonFinite(const VolumeView& view, std::int64_t* firstIndex)
{
  return detail::dispatchScalarType(view.type, [&](auto tag) -> std::int64_t {
    using T = decltype(tag);
    if (std::is_integral<T>::value || view.voxelCount() <= 0)
    {
      return 0;
    }
    const T* data = static_cast<const T*>(view.data);
    const std::int64_t n = view.voxelCount();
    std::mutex merge;
    std::int64_t count = 0;
    std::int64_t first = n;
    const int threads = detail::resolveThreadCount(0);
    detail::parallelFor(n, 4 * threads, threads, [&](std::int64_t begin, std::int64_t end) {
      std::int64_t localCount = 0, localFirst = n;
      for (std::int64_t i = begin; i < end; ++i)
      {
        // Written without a branch on the value so that the loop vectorises.
        const bool bad = !std::isfinite(data[i * view.voxelStride]);
        localCount += bad;
        localFirst = bad && localFirst == n ? i : localFirst;
      }
      std::lock_guard<std::mutex> lock(merge);
      count += localCount;
      first = std::min(first, localFirst);
    });
    if (count > 0 && firstIndex)
    {
      *firstIndex = first;
    }
    return count;
  });
}

Status checkFiniteValues(const VolumeView& volume)
{
  std::int64_t first = -1;
  const std::int64_t count = countNonFinite(volume, &first);
  return count > 0 ? Status::nonFinite(count, first) : Status::success();
}

} // namespace vao
