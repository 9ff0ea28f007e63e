// computeAmbientOcclusion: the estimators of Estimators.h fed by the streamed box moments
// (and the box extrema for CDF Reconstruction), the box histograms of Histogram CDF, or the
// exact references; with the voxel's value, the iso value or the smoothed query as q.
#include "cpu/box_statistics/BoxEngine.h"
#include "cpu/box_statistics/EstimatorRows.h"
#include "cpu/box_statistics/TransferFunctionOpenness.h"
#include "cpu/common/ConcurrentRange.h"
#include "cpu/exact_reference/ExactReference.h"
#include "cpu/histogram_cdf/HistogramChannels.h"
#include "cpu/ray_casting/ExactRays.h"
#include "cpu/ray_casting/RayEstimate.h"
#include "cpu/simd/CpuDispatch.h"
#include "cpu/smoothed_query/SmoothedQuery.h"
#include "vao/Storage.h"

#include "vao/Validation.h"

#include <algorithm>
#include <cmath>
#include <vector>

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

constexpr double kLargestSmoothedMagnitude = 1e300;

/// The openness (from the streamed moments) and the variance of the box, as asked.
template <class T>
Status separableOpenness(const VolumeView& view, const Region& region,
  const AmbientOcclusionParameters& p, const AmbientOcclusionOutput& output, const double* query,
  const ValueScan& scan, const Execution& execution)
{
  const detail::TypedVolume<T> volume(view);
  const detail::BoxGeometry geometry(view.dims, region, p.radius);
  const bool withExtrema = output.openness && p.method == Method::CdfReconstruction;
  const bool voxelQuery = p.queryMode == QueryMode::VoxelValue;
  const detail::MomentScale scale =
    detail::momentScale(volume, scan.minimum, scan.maximum, p.momentBasis);
  // Chebyshev and the Gaussian CDF take exact sums as they are (opennessRow).
  const bool fromSums = p.method == Method::Chebyshev || p.method == Method::GaussianCdf;
  // CDF Reconstruction takes the mean alone from the moments.
  const bool variance =
    output.variance || (output.openness && p.method != Method::CdfReconstruction);
  // The openness alone reads raw rows where they come (16-bit voxels).
  const bool moments = output.variance != nullptr || !output.openness || !fromSums;
  const detail::RowContents contents{ withExtrema, moments, output.openness && voxelQuery && !query,
    variance, output.openness && !output.variance };
  // Kept where the rows' extremes take vector instructions; the plain loop would cost
  // several times the separate, threaded pass the caller then makes (vao/ValueRanges.h).
  const bool keepRange = output.openness && output.opennessRange && detail::cpuHasAvx2();
  detail::ConcurrentRange range;
  const bool ok = detail::forEachNeighbourhoodRow(volume, geometry, scale, contents, execution,
    [&](const detail::NeighbourhoodRow& row)
    {
      if (output.variance)
      {
        for (std::int64_t i = 0; i < row.size; ++i)
          output.variance[row.index + i] =
            static_cast<float>(reportedVariance(row.variance[i], row.roundingVariance));
      }
      if (output.openness)
      {
        // A raw row reads its own values where query and row.value are null (opennessRow).
        const double* q = query ? query + row.index : (voxelQuery ? row.value : nullptr);
        detail::opennessRow(p.method, p.erfMode, row, q, p.isoValue, output.openness + row.index);
        if (keepRange)
          range.add(output.openness + row.index, row.size);
      }
    });
  if (ok && keepRange)
    *output.opennessRange = range.result();
  return ok ? Status::success() : Status::cancelled();
}

/// The parameters' own checks (the volume's come after).
Status checkParameters(const AmbientOcclusionParameters& p)
{
  if (p.queryMode == QueryMode::IsoValue)
  {
    return checkFiniteParameter(p.isoValue, "the iso value");
  }
  if (p.queryMode == QueryMode::SmoothedValue)
  {
    const std::string why = checkQuerySmoothing(p.querySmoothing);
    if (!why.empty())
      return Status::failure(why);
  }
  if (p.method == Method::HistogramCdf)
  {
    return checkHistogramThresholds(p.thresholds);
  }
  if (p.method == Method::TransferFunction)
  {
    return checkOpacityFunction(p.opacity);
  }
  if (isRayMethod(p.method))
  {
    const Status opacity = checkOpacityFunction(p.opacity);
    return opacity.ok ? checkRayParameters(p.rays) : opacity;
  }
  return Status::success();
}

/// The request's checks: the parameters', then the volume and the region (with the scan of
/// the values that the moments need, or, for the other methods, a scan of float volumes
/// for non-finite values), then the range the smoothed query can take. `scan` keeps what
/// was scanned (nothing for integer volumes without moments).
Status validateRequest(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, bool moments, ValueScan& scan)
{
  Status status = checkParameters(parameters);
  if (status.ok && moments)
  {
    status = validateMomentRequest(volume, region, parameters.radius, scan);
  }
  else if (status.ok)
  {
    status = validate(volume, region, parameters.radius);
    if (status.ok && !scalarTypeIsIntegral(volume.type))
      status = finiteStatus(scan = scanValues(volume));
  }
  if (status.ok && isRayMethod(parameters.method) && parameters.opacity.logScale)
  {
    // Interpolated values lie between the voxels' own: positive voxels and points keep
    // every sample where the log scale is defined.
    const double lowest = scalarTypeIsIntegral(volume.type) ? valueRange(volume)[0] : scan.minimum;
    const bool positivePoints = std::all_of(parameters.opacity.nodes.begin(),
      parameters.opacity.nodes.end(), [](const OpacityNode& node) { return node.x > 0.0; });
    if (!(lowest > 0.0) || !positivePoints)
      status = Status::failure("the opacity function is undefined at some of the values: its log "
                               "scale needs values and points above 0");
  }
  if (status.ok && parameters.queryMode == QueryMode::SmoothedValue &&
    std::max(std::abs(scan.minimum), std::abs(scan.maximum)) > kLargestSmoothedMagnitude)
  {
    // The smoothed query sums differences of values: beyond this they overflow double.
    status = Status::failure(
      "the smoothed query needs values within +-1e300 (their differences would overflow "
      "double precision): rescale the data (e.g. with the Calculator) first");
  }
  return status;
}

/// The openness of the methods that do not come from the streamed moments: Histogram CDF
/// (box histograms), Transfer Function (the box mean of the opacity) and the exact
/// references. `q` is the smoothed query, or null. Transfer Function keeps the range of what
/// it writes in `range` (when not null).
Status separateOpenness(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const double* q, float* openness,
  OutputRange* range, const Execution& stage)
{
  if (parameters.method == Method::HistogramCdf)
  {
    detail::HistogramQuery source;
    source.values = q;
    source.isoValue = parameters.queryMode == QueryMode::IsoValue ? &parameters.isoValue : nullptr;
    if (!detail::computeHistogramOpenness(
          volume, region, parameters.radius, parameters.thresholds, source, openness, range, stage))
      return Status::cancelled();
    return Status::success();
  }
  if (parameters.method == Method::TransferFunction)
  {
    return detail::computeTransferFunctionOpenness(
      volume, region, parameters.radius, parameters.opacity, openness, range, stage);
  }
  if (parameters.method == Method::ExactRays)
  {
    return detail::computeExactRays(volume, region, parameters, openness, range, stage);
  }
  if (parameters.method == Method::Rays)
  {
    return detail::computeRays(volume, region, parameters, openness, range, stage);
  }
  return detail::computeExactOpenness(volume, region, parameters, q, openness, stage);
}

/// The request checked, then its stages: the smoothed query, the openness of the methods
/// that do not stream the moments (separateOpenness), and what the moments give (the
/// separable methods' openness, the variance).
Status ambientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution)
{
  if (output.opennessRange)
    *output.opennessRange = OutputRange{}; // unknown unless the pass that writes it keeps it
  const bool moments = output.variance || (output.openness && isSeparableMethod(parameters.method));
  ValueScan scan;
  const Status status = validateRequest(volume, region, parameters, moments, scan);
  if (!status.ok)
  {
    return status;
  }
  // Stages of the progress: the smoothed query, the openness, the variance.
  // Transfer Function and the rays read the opacity, not a query.
  const bool smoothed = parameters.queryMode == QueryMode::SmoothedValue &&
    parameters.method != Method::TransferFunction && !isRayMethod(parameters.method);
  const bool separate = output.openness && !isSeparableMethod(parameters.method);
  const double queryEnd = smoothed ? 0.2 : 0.0;
  const double opennessEnd = separate ? (output.variance ? 0.9 : 1.0) : queryEnd;
  StorageArray<double> query; // computeSmoothedQuery writes every voxel
  if (smoothed && output.openness)
  {
    query.resize(static_cast<std::size_t>(region.voxelCount()));
    if (!detail::computeSmoothedQuery(volume, region, parameters.querySmoothing, query.data(),
          detail::stageExecution(execution, 0.0, queryEnd)))
      return Status::cancelled();
  }
  const double* q = query.empty() ? nullptr : query.data();
  if (separate)
  {
    const Status openness = separateOpenness(volume, region, parameters, q, output.openness,
      output.opennessRange, detail::stageExecution(execution, queryEnd, opennessEnd));
    if (!openness.ok)
      return openness;
  }
  if (!moments)
  {
    return Status::success();
  }
  AmbientOcclusionOutput separable = output;
  if (separate)
  {
    separable.openness = nullptr; // done: only the variance comes from the moments
  }
  return detail::dispatchScalarType(volume.type,
    [&](auto tag)
    {
      return separableOpenness<decltype(tag)>(volume, region, parameters, separable, q, scan,
        detail::stageExecution(execution, opennessEnd, 1.0));
    });
}

} // namespace

int querySmoothingHalfWidth(double sigma)
{
  return std::isfinite(sigma) && sigma > 0.0
    ? static_cast<int>(std::ceil(3.0 * std::min(sigma, kMaximumQuerySmoothing)))
    : 0;
}

Status computeAmbientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution)
{
  return catchOutOfMemory("the working buffers of Volumetric AO (box statistics, histograms, the "
                          "smoothed query, the exact references' rows)",
    [&] { return ambientOcclusion(volume, region, parameters, output, execution); });
}

} // namespace vao
