// computeAmbientOcclusion: the estimators of Estimators.h fed by the streamed box moments
// (and the box extrema for CDF Reconstruction), or the exact references.
#include "BoxEngine.h"
#include "ExactReference.h"

#include <limits>
#include <sstream>

namespace vao
{

const char* scalarTypeName(ScalarType type)
{
  static const char* const names[] = { "int8", "uint8", "int16", "uint16", "int32", "uint32",
    "int64", "uint64", "float32", "float64" };
  return names[static_cast<int>(type)];
}

Status validate(const VolumeView& volume, const Region& region, const Radius& radius)
{
  std::ostringstream why;
  if (!volume.data || volume.voxelCount() <= 0)
  {
    why << "the volume is empty (" << volume.dims[0] << " x " << volume.dims[1] << " x "
        << volume.dims[2] << " voxels)";
  }
  else if (volume.voxelStride < 1)
  {
    why << "the voxel stride must be at least 1 (got " << volume.voxelStride << ")";
  }
  else if (radius.x < 0 || radius.y < 0 || radius.z < 0)
  {
    why << "the radius must not be negative (got " << radius.x << ", " << radius.y << ", "
        << radius.z << " voxels)";
  }
  else
  {
    for (int a = 0; a < 3; ++a)
    {
      if (region.size[a] <= 0 || region.begin[a] < 0 ||
        region.begin[a] + region.size[a] > volume.dims[a])
      {
        why << "the output region [" << region.begin[a] << ", " << region.begin[a] + region.size[a]
            << ") of axis " << a << " is empty or outside the volume's " << volume.dims[a]
            << " voxels";
        break;
      }
    }
  }
  const std::string message = why.str();
  return message.empty() ? Status::success() : Status::failure(message);
}

namespace
{

template <class T>
Status separableOpenness(const VolumeView& view, const Region& region,
  const AmbientOcclusionParameters& p, const AmbientOcclusionOutput& output,
  const Execution& execution)
{
  const detail::TypedVolume<T> volume(view);
  const detail::BoxGeometry geometry(view.dims, region, p.radius);
  const bool withExtrema = output.openness && p.method == Method::CdfReconstruction;
  const bool voxelQuery = p.queryMode == QueryMode::VoxelValue;
  const bool ok = detail::forEachNeighbourhood(volume, geometry, withExtrema, execution,
    [&](const detail::VoxelNeighbourhood& voxel) {
      if (output.variance)
      {
        output.variance[voxel.index] = static_cast<float>(voxel.stats.variance);
      }
      if (output.openness)
      {
        const double q = voxelQuery ? voxel.value : p.isoValue;
        output.openness[voxel.index] =
          static_cast<float>(opennessFromStats(p.method, q, voxel.stats, p.erfMode));
      }
    });
  return ok ? Status::success() : Status::cancelled();
}

} // namespace

Status computeAmbientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution)
{
  Status status = validate(volume, region, parameters.radius);
  if (!status.ok)
  {
    return status;
  }
  if (parameters.queryMode == QueryMode::IsoValue && !std::isfinite(parameters.isoValue))
  {
    return Status::failure("the iso value must be a finite number");
  }
  AmbientOcclusionOutput separable = output;
  if (!isSeparableMethod(parameters.method))
  {
    const bool withVariance = output.variance != nullptr;
    const Execution exact = detail::stageExecution(execution, 0.0, withVariance ? 0.9 : 1.0);
    if (output.openness)
    {
      status = detail::computeExactOpenness(volume, region, parameters, output.openness, exact);
    }
    if (!status.ok || !withVariance)
    {
      return status;
    }
    separable.openness = nullptr; // the variance still comes from the moments
  }
  return detail::dispatchScalarType(volume.type, [&](auto tag) {
    return separableOpenness<decltype(tag)>(volume, region, parameters, separable,
      isSeparableMethod(parameters.method) ? execution
                                           : detail::stageExecution(execution, 0.9, 1.0));
  });
}

std::int64_t countNonFinite(const VolumeView& view, std::int64_t* firstIndex)
{
  return detail::dispatchScalarType(view.type, [&](auto tag) -> std::int64_t {
    using T = decltype(tag);
    if (std::is_integral<T>::value)
    {
      return 0;
    }
    const T* data = static_cast<const T*>(view.data);
    std::int64_t count = 0;
    const std::int64_t n = view.voxelCount();
    for (std::int64_t i = 0; i < n; ++i)
    {
      if (!std::isfinite(static_cast<double>(data[i * view.voxelStride])))
      {
        if (count == 0 && firstIndex)
        {
          *firstIndex = i;
        }
        ++count;
      }
    }
    return count;
  });
}

std::array<double, 2> valueRange(const VolumeView& view)
{
  return detail::dispatchScalarType(view.type, [&](auto tag) -> std::array<double, 2> {
    using T = decltype(tag);
    const T* data = static_cast<const T*>(view.data);
    const std::int64_t n = view.voxelCount();
    if (n <= 0)
    {
      return { 0.0, 0.0 };
    }
    T lo = data[0], hi = data[0];
    for (std::int64_t i = 1; i < n; ++i)
    {
      const T v = data[i * view.voxelStride];
      lo = v < lo ? v : lo;
      hi = hi < v ? v : hi;
    }
    return { static_cast<double>(lo), static_cast<double>(hi) };
  });
}

} // namespace vao
