// The checks every entry point of the kernel library makes, written once. Each returns
// Status::success() or a failure whose message names what was wrong and where; the VTK
// filters pass the message on (adding their own array and voxel coordinates) and check
// only what is VTK's (arrays, enums).
#pragma once

#include "vao/AmbientOcclusion.h"

#include <array>
#include <functional>

namespace vao
{

/// Data present, every axis at least `minimumPerAxis` voxels, stride >= 1.
/// `method` names what needs them in the message when minimumPerAxis > 1.
Status checkVolume(
  const VolumeView& volume, std::int64_t minimumPerAxis = 1, const char* method = nullptr);

/// The region lies in the volume and is not empty.
Status checkRegion(const VolumeView& volume, const Region& region);

/// No negative half-width.
Status checkRadius(const Radius& radius);

/// Every spacing finite and > 0 (`what`: "the spacing", "the volume's spacing", ...).
Status checkSpacing(const std::array<double, 3>& spacing, const char* what = "the spacing");

/// Every coordinate finite.
Status checkFinitePoint(const std::array<double, 3>& point, const char* what);

/// A parameter that must be a finite number.
Status checkFiniteParameter(double value, const char* what);

/// "" or why sigma is not an accepted QuerySmoothing: finite, > 0, at most
/// kMaximumQuerySmoothing voxels.
std::string checkQuerySmoothing(double sigma);

/// Histogram CDF's thresholds: 1 to kMaximumHistogramBins, finite, strictly ascending.
Status checkHistogramThresholds(const std::vector<double>& thresholds);

/// The Transfer Function method's opacity: at least one node; every x, opacity, midpoint
/// and sharpness finite; x ascending; opacity, midpoint and sharpness in [0, 1].
Status checkOpacityFunction(const OpacityFunction& function);

/// The rays of Exact Rays and Rays: radius, spacing and opacity unit distance finite and
/// positive (the unit distance 0 for the smallest spacing); a finite direction matrix with
/// unit columns at right angles; 1 <= rayCount <= kMaximumRayCount; and no more than 2^31
/// samples per ray (R over half the smallest spacing).
Status checkRayParameters(const RayParameters& rays);

/// What one parallel pass over the values finds: the non-finite ones, and the range of
/// the finite ones (0, 0 when there is none).
struct ValueScan
{
  std::int64_t nonFiniteCount = 0;
  std::int64_t firstNonFinite = -1;
  double minimum = 0.0;
  double maximum = 0.0;
};

/// One pass over the values, on every core.
ValueScan scanValues(const VolumeView& volume);

/// Whether the box statistics of this type need a scan: floating-point types (NaN,
/// infinity) and the integers wider than 16 bits (their double sums round, by the range).
inline bool needsValueScan(ScalarType type)
{
  return type != ScalarType::Int8 && type != ScalarType::UInt8 && type != ScalarType::Int16 &&
    type != ScalarType::UInt16;
}

/// Status::nonFinite (count and first index) when the scan found any, else success.
Status finiteStatus(const ValueScan& scan);

/// The largest magnitude whose moments (sums of squares over any box) stay finite in double.
constexpr double kLargestMomentMagnitude = 1e140;

/// A failure when the scanned values exceed kLargestMomentMagnitude in magnitude.
Status checkMomentMagnitude(const ValueScan& scan);

/// The spans of values whose variances the moment pyramid's float32 levels hold: beyond
/// 1e18 the variance of a box of them can pass float's largest (3.4e38); below 1e-17 the
/// variance of a box with a tenth of them changed falls under its smallest normal
/// (1.2e-38), and flat and textured regions look alike.
constexpr double kLargestPyramidSpan = 1e18;
constexpr double kSmallestPyramidSpan = 1e-17;

/// A failure when the scanned values span more than kLargestPyramidSpan, or less than
/// kSmallestPyramidSpan without being constant.
Status checkPyramidSpan(const ValueScan& scan);

/// No NaN or infinite voxel; otherwise Status::nonFinite (count and first index). One
/// parallel pass over the data (none for integer types).
Status checkFiniteValues(const VolumeView& volume);

/// f(), with std::bad_alloc from anywhere inside it (its buffers, its worker threads)
/// turned into Status::noMemory(what): the entry points never throw. A template, not a
/// std::function, whose making could itself allocate, and throw, before the guard is up.
template <class F>
Status catchOutOfMemory(const char* what, F&& f)
{
  try
  {
    return f();
  }
  catch (const std::bad_alloc&)
  {
    return Status::noMemory(what);
  }
}

/// The checks of a call on box moments (Volumetric AO on the CPU or the GPU): validate(),
/// then, where the type needs it, one scan for non-finite values and for magnitudes whose
/// squares overflow. `scan` receives the scan (empty for the types of up to 16 bits).
Status validateMomentRequest(
  const VolumeView& volume, const Region& region, const Radius& radius, ValueScan& scan);

} // namespace vao
