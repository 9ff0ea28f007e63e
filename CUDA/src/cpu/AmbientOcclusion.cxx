// computeAmbientOcclusion: the estimators of Estimators.h fed by the streamed box moments
// (and the box extrema for CDF Reconstruction), or the exact references.
#include "BoxEngine.h"
#include "ExactReference.h"

#include "vao/Validation.h"


namespace vao
{

const char* scalarTypeName(ScalarType type)
{
  static const char* const names[] = { "int8", "uint8", "int16", "uint16", "int32", "uint32",
    "int64", "uint64", "float32", "float64" };
  return names[static_cast<int>(type)];
}

namespace
{

template <class T>
Status separableOpenness(const VolumeView& view, const Region& region,
  const AmbientOcclusionParameters& p, const AmbientOcclusionOutput& output,
  const ValueScan& scan, const Execution& execution)
{
  const detail::TypedVolume<T> volume(view);
  const detail::BoxGeometry geometry(view.dims, region, p.radius);
  const bool withExtrema = output.openness && p.method == Method::CdfReconstruction;
  const bool voxelQuery = p.queryMode == QueryMode::VoxelValue;
  const detail::MomentScale scale = detail::momentScale(volume, scan.minimum, scan.maximum);
  const bool ok = detail::forEachNeighbourhood(volume, geometry, scale, withExtrema, execution,
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

namespace
{

Status ambientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution)
{
  Status status = parameters.queryMode == QueryMode::IsoValue
    ? checkFiniteParameter(parameters.isoValue, "the iso value")
    : Status::success();
  ValueScan scan;
  if (status.ok)
    status = validateMomentRequest(volume, region, parameters.radius, scan);
  if (!status.ok)
  {
    return status;
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
    return separableOpenness<decltype(tag)>(volume, region, parameters, separable, scan,
      isSeparableMethod(parameters.method) ? execution
                                           : detail::stageExecution(execution, 0.9, 1.0));
  });
}

} // namespace

Status computeAmbientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution)
{
  return catchOutOfMemory("the working buffers of Volumetric AO (box statistics or the exact count)",
    [&] { return ambientOcclusion(volume, region, parameters, output, execution); });
}

} // namespace vao
