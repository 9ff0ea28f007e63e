// Histogram CDF on the CPU (HistogramChannels.cxx).
#pragma once

#include "vao/AmbientOcclusion.h"

#include <vector>

namespace vao
{
namespace detail
{

/// Where the query comes from: per voxel of the region (`values`, x fastest), one value
/// for all (`isoValue`), or, when both are null, the voxel's own value.
struct HistogramQuery
{
  const double* values = nullptr;
  const double* isoValue = nullptr;
};

/// Histogram CDF openness of the region's voxels for the ascending thresholds (at most
/// kMaximumHistogramBins of them), and their range into `range` unless it is null.
/// Returns false when cancelled.
bool computeHistogramOpenness(const VolumeView& volume, const Region& region, const Radius& radius,
  const std::vector<double>& thresholds, const HistogramQuery& query, float* openness,
  OutputRange* range, const Execution& execution);

} // namespace detail
} // namespace vao
