// The argument checks of every entry point (vao/Validation.h), and the parallel scan for
// non-finite values.
#include "vao/Validation.h"
#include "vao/HistogramCdf.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <new>
#include <sstream>
#include <type_traits>

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
    why << (method ? method : "the method") << " needs a 3-D volume with at least "
        << minimumPerAxis << " voxels per axis (got " << d[0] << " x " << d[1] << " x " << d[2]
        << ")";
  }
  const std::string message = why.str();
  return message.empty() ? Status::success() : Status::failure(message);
}

Status checkRegion(const VolumeView& volume, const Region& region)
{
  for (int a = 0; a < 3; ++a)
  {
    if (region.size[a] <= 0 || region.begin[a] < 0 ||
      region.begin[a] + region.size[a] > volume.dims[a])
    {
      std::ostringstream why;
      why << "the output region [" << region.begin[a] << ", " << region.begin[a] + region.size[a]
          << ") of axis " << a << " is empty or outside the volume's " << volume.dims[a]
          << " voxels";
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
      why << what << " must be finite and positive (got " << spacing[0] << ", " << spacing[1]
          << ", " << spacing[2] << ")";
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

ValueScan scanValues(const VolumeView& view)
{
  return detail::dispatchScalarType(view.type,
    [&](auto tag) -> ValueScan
    {
      using T = decltype(tag);
      const std::int64_t n = view.voxelCount();
      if (n <= 0 || !view.data)
      {
        return {};
      }
      const T* data = static_cast<const T*>(view.data);
      std::mutex merge;
      ValueScan total;
      total.firstNonFinite = n;
      bool anyFinite = false;
      const int threads = detail::resolveThreadCount(0);
      const std::int64_t stride = view.voxelStride;
      detail::parallelFor(n, 4 * threads, threads,
        [&](std::int64_t begin, std::int64_t end)
        {
          std::int64_t count = 0, first = n;
          // The range of the finite values: +-infinity start values, so no branch on the
          // first one. The count of non-finite values and the range come first, in a loop
          // without a data-dependent index (it vectorises; integers are all finite); the first
          // non-finite value is looked for only where there is one.
          T lo = std::numeric_limits<T>::has_infinity ? std::numeric_limits<T>::infinity()
                                                      : std::numeric_limits<T>::max();
          T hi = std::numeric_limits<T>::has_infinity ? -std::numeric_limits<T>::infinity()
                                                      : std::numeric_limits<T>::lowest();
          auto scan = [&](auto unit)
          {
            const std::int64_t step = decltype(unit)::value ? 1 : stride;
            for (std::int64_t i = begin; i < end; ++i)
            {
              const T v = data[i * step];
              const bool bad = !std::is_integral<T>::value && !(v - v == v - v); // NaN or infinite
              count += bad;
              lo = bad || !(v < lo) ? lo : v;
              hi = bad || !(hi < v) ? hi : v;
            }
          };
          if (stride == 1)
            scan(std::true_type{});
          else
            scan(std::false_type{});
          for (std::int64_t i = begin; count > 0 && i < end && first == n; ++i)
          {
            first = std::isfinite(static_cast<double>(data[i * stride])) ? n : i;
          }
          std::lock_guard<std::mutex> lock(merge);
          total.nonFiniteCount += count;
          total.firstNonFinite = std::min(total.firstNonFinite, first);
          if (count < end - begin)
          {
            total.minimum = anyFinite ? std::min(total.minimum, static_cast<double>(lo))
                                      : static_cast<double>(lo);
            total.maximum = anyFinite ? std::max(total.maximum, static_cast<double>(hi))
                                      : static_cast<double>(hi);
            anyFinite = true;
          }
        });
      if (total.nonFiniteCount == 0)
      {
        total.firstNonFinite = -1;
      }
      return total;
    });
}

std::string checkQuerySmoothing(double sigma)
{
  if (std::isfinite(sigma) && sigma > 0.0 && sigma <= kMaximumQuerySmoothing)
  {
    return std::string();
  }
  std::ostringstream why;
  why << "QuerySmoothing (the smoothed query's sigma in voxels) must be a finite number in (0, "
      << kMaximumQuerySmoothing << "] (got " << sigma << ")";
  return why.str();
}

Status checkHistogramThresholds(const std::vector<double>& thresholds)
{
  if (thresholds.empty() || thresholds.size() > static_cast<std::size_t>(kMaximumHistogramBins))
  {
    return Status::failure("Histogram CDF needs 1 to " + std::to_string(kMaximumHistogramBins) +
      " thresholds (got " + std::to_string(thresholds.size()) + ")");
  }
  for (std::size_t k = 0; k < thresholds.size(); ++k)
  {
    if (!std::isfinite(thresholds[k]) || (k > 0 && !(thresholds[k] > thresholds[k - 1])))
    {
      return Status::failure(
        "Histogram CDF's thresholds must be finite and strictly ascending (threshold " +
        std::to_string(k) + " is not)");
    }
  }
  return Status::success();
}

Status checkOpacityFunction(const OpacityFunction& function)
{
  if (function.nodes.empty())
  {
    return Status::failure(
      "the opacity function has no points: give it at least one (x, opacity) point");
  }
  for (std::size_t k = 0; k < function.nodes.size(); ++k)
  {
    const OpacityNode& node = function.nodes[k];
    const std::string which = "opacity point " + std::to_string(k);
    if (!std::isfinite(node.x) || !std::isfinite(node.y) || !std::isfinite(node.midpoint) ||
      !std::isfinite(node.sharpness))
    {
      return Status::failure(which + " is not finite (NaN or infinity)");
    }
    if (node.y < 0.0 || node.y > 1.0)
    {
      return Status::failure(
        which + " has opacity " + std::to_string(node.y) + ": opacities must lie in [0, 1]");
    }
    if (node.midpoint < 0.0 || node.midpoint > 1.0 || node.sharpness < 0.0 || node.sharpness > 1.0)
    {
      return Status::failure(which + "'s midpoint and sharpness must lie in [0, 1]");
    }
    if (k > 0 && node.x < function.nodes[k - 1].x)
    {
      return Status::failure(
        "the opacity function's points must be in ascending order of value (" + which + " is not)");
    }
  }
  return Status::success();
}

Status checkRayParameters(const RayParameters& rays)
{
  std::ostringstream why;
  if (!std::isfinite(rays.radius) || !(rays.radius > 0.0))
    why << "the rays' radius must be finite and positive (got " << rays.radius << ")";
  else if (!checkSpacing(rays.spacing).ok)
    return checkSpacing(rays.spacing);
  else if (!std::isfinite(rays.opacityUnitDistance) || rays.opacityUnitDistance < 0.0)
    why << "the opacity unit distance must be finite and positive, or 0 for the smallest "
           "spacing (got "
        << rays.opacityUnitDistance << ")";
  else if (rays.rayCount < 1 || rays.rayCount > kMaximumRayCount)
    why << "the ray count must lie in [1, " << kMaximumRayCount << "] (got " << rays.rayCount
        << ")";
  if (!why.str().empty())
    return Status::failure(why.str());
  const std::array<double, 9>& d = rays.direction;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      const double dot = d[i] * d[j] + d[3 + i] * d[3 + j] + d[6 + i] * d[6 + j];
      if (!std::isfinite(dot) || std::abs(dot - (i == j ? 1.0 : 0.0)) > 1e-6)
        return Status::failure("the direction matrix must be a rotation or reflection (unit "
                               "columns at right angles), as vtkImageData's is");
    }
  }
  const double smallest = std::min({ rays.spacing[0], rays.spacing[1], rays.spacing[2] });
  if (!(rays.radius / (smallest / 2.0) <= 2147483647.0))
  {
    why << "the rays' radius " << rays.radius << " is more than 2^30 times the smallest spacing "
        << smallest << ": use a smaller radius";
    return Status::failure(why.str());
  }
  return Status::success();
}

Status finiteStatus(const ValueScan& scan)
{
  return scan.nonFiniteCount > 0 ? Status::nonFinite(scan.nonFiniteCount, scan.firstNonFinite)
                                 : Status::success();
}

Status checkMomentMagnitude(const ValueScan& scan)
{
  const double largest = std::max(std::abs(scan.minimum), std::abs(scan.maximum));
  if (largest <= kLargestMomentMagnitude)
  {
    return Status::success();
  }
  std::ostringstream why;
  why << "the values reach " << largest << " in magnitude; above " << kLargestMomentMagnitude
      << " their squared sums overflow double precision: rescale the data (e.g. with the "
         "Calculator) first";
  return Status::failure(why.str());
}

Status checkPyramidSpan(const ValueScan& scan)
{
  const double span = scan.maximum - scan.minimum;
  const bool tooWide = span > kLargestPyramidSpan;
  if (!tooWide && !(span > 0.0 && span < kSmallestPyramidSpan))
  {
    return Status::success();
  }
  std::ostringstream why;
  why << "the values span " << span << " (" << scan.minimum << " to " << scan.maximum << "); "
      << (tooWide ? "above " : "below ") << (tooWide ? kLargestPyramidSpan : kSmallestPyramidSpan)
      << " their variances " << (tooWide ? "overflow" : "underflow")
      << " the pyramid's float32 levels: rescale the data (e.g. with the Calculator) first";
  return Status::failure(why.str());
}

Status validateMomentRequest(
  const VolumeView& volume, const Region& region, const Radius& radius, ValueScan& scan)
{
  Status status = validate(volume, region, radius);
  // One pass for the non-finite values and the range the double sums' rounding depends
  // on; none for the types of up to 16 bits (no NaN, exact sums).
  scan = status.ok && needsValueScan(volume.type) ? scanValues(volume) : ValueScan{};
  if (status.ok)
    status = finiteStatus(scan);
  if (status.ok)
    status = checkMomentMagnitude(scan);
  return status;
}

std::int64_t countNonFinite(const VolumeView& view, std::int64_t* firstIndex)
{
  if (scalarTypeIsIntegral(view.type))
  {
    return 0;
  }
  const ValueScan scan = scanValues(view);
  if (scan.nonFiniteCount > 0 && firstIndex)
  {
    *firstIndex = scan.firstNonFinite;
  }
  return scan.nonFiniteCount;
}

Status checkFiniteValues(const VolumeView& volume)
{
  return catchOutOfMemory("the scan for non-finite values",
    [&]
    {
      return scalarTypeIsIntegral(volume.type) ? Status::success()
                                               : finiteStatus(scanValues(volume));
    });
}

std::array<double, 2> valueRange(const VolumeView& volume)
{
  const ValueScan scan = scanValues(volume);
  return { scan.minimum, scan.maximum };
}

ShiftSamples momentShiftSamples(
  const VolumeView& volume, const Region& region, const Index3& offset, const Index3& wholeDims)
{
  return detail::dispatchScalarType(volume.type,
    [&](auto tag)
    {
      return detail::shiftSamples(
        detail::TypedVolume<decltype(tag)>(volume), region, offset, wholeDims);
    });
}

} // namespace vao
