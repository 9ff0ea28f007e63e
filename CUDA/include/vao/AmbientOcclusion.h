// Host interface of the VolumetricAO kernel library: no VTK, plain C++17.
//
// A volume is a block of voxels (x fastest) of any scalar type, read in place through a
// stride (so one component of a multi-component array needs no converted copy). Results
// are computed for a sub-region of that block; every neighbourhood is clipped to the
// block, which the caller makes equal to the data set's whole extent (or to a piece
// grown by the radius and clipped to the whole extent: the same thing for the region).
#pragma once

#include "vao/Estimators.h"
#include "vao/RayCasting.h"
#include "vao/TransferFunction.h"

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <new>
#include <string>
#include <vector>

namespace vao
{

enum class ScalarType : int
{
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Int64,
  UInt64,
  Float32,
  Float64,
};

const char* scalarTypeName(ScalarType type);

/// True for the integer types (which hold no NaN or infinity).
inline bool scalarTypeIsIntegral(ScalarType type)
{
  return type != ScalarType::Float32 && type != ScalarType::Float64;
}

using Index3 = std::array<std::int64_t, 3>;

struct VolumeView
{
  const void* data = nullptr; // first voxel's (chosen) component
  ScalarType type = ScalarType::Float32;
  Index3 dims = { 0, 0, 0 };
  std::int64_t voxelStride = 1; // elements between consecutive voxels (components)

  std::int64_t voxelCount() const { return dims[0] * dims[1] * dims[2]; }
};

/// Sub-block [begin, begin + size) of the volume for which results are written.
struct Region
{
  Index3 begin = { 0, 0, 0 };
  Index3 size = { 0, 0, 0 };

  static Region whole(const VolumeView& volume) { return { { 0, 0, 0 }, volume.dims }; }
  std::int64_t voxelCount() const { return size[0] * size[1] * size[2]; }
};

/// Half-widths of the box neighbourhood, in voxels, per axis.
struct Radius
{
  int x = 0;
  int y = 0;
  int z = 0;
};

enum class QueryMode : int
{
  VoxelValue = 0,
  IsoValue = 1,
  SmoothedValue =
    2, // docs/methods.md section 9: a normalised Gaussian average of v around the voxel
};

/// The accepted QuerySmoothing (sigma in voxels): the window of ceil(3 sigma) voxels each
/// side costs O(sigma) per voxel and pass, and wider ones blur structures that AO shows.
constexpr double kMaximumQuerySmoothing = 100.0;

/// What the moment sums of a float (or wider than 16-bit) volume are taken about: the
/// shift subtracted before squaring and the range of the data's values, which bounds the
/// sums' rounding and so the variance at or below which a box counts as flat
/// (Estimators.h). NaN, the default: the volume's own (the mean of its momentShiftSamples,
/// its range). A piece of a larger data set passes the whole data set's, so that nearly
/// flat boxes get the whole volume's answers.
struct MomentBasis
{
  double shift = std::numeric_limits<double>::quiet_NaN();
  double lowest = std::numeric_limits<double>::quiet_NaN();
  double highest = std::numeric_limits<double>::quiet_NaN();
};

struct AmbientOcclusionParameters
{
  Method method = Method::GaussianCdf;
  Radius radius;
  QueryMode queryMode = QueryMode::VoxelValue;
  double isoValue = 0.0;
  ErfMode erfMode = ErfMode::Exact;
  double querySmoothing = 1.0; // sigma in voxels of QueryMode::SmoothedValue
  // Histogram CDF: the ascending thresholds t_k, fixed from the whole data set's values
  // (vao/HistogramCdf.h), never from one piece's.
  std::vector<double> thresholds;
  // Transfer Function, Exact Rays and Rays: the opacity (checkOpacityFunction).
  OpacityFunction opacity;
  // The separable methods and the variance on a piece of a data set: the data set's basis.
  MomentBasis momentBasis;
  // Exact Rays and Rays: the rays' world frame (`radius` above is then their reach in
  // voxels, rayReach, which the volume block must hold around the region where it is not
  // the whole extent).
  RayParameters rays;
};

/// The half-width in voxels of the smoothed query's window (ceil(3 sigma)): a piece of a
/// data set must be grown by it, as by the radius, for its voxels to get the serial query.
int querySmoothingHalfWidth(double sigma);

/// How the work runs: thread count, progress in [0, 1] and cancellation. The callbacks are
/// invoked on the calling thread only, so they may touch non-thread-safe state (VTK).
struct Execution
{
  int threads = 0; // 0: every hardware thread
  int device = -1; // CUDA device (vao/Cuda.h, deviceStatus); -1: chosen by the node-local rank
  std::function<void(double)> progress;
  std::function<bool()> abortRequested;
};

/// The lowest and highest of the values a pass wrote, where it kept them (known): a caller
/// that needs the range (VTK's range cache) then need not read the array again.
struct OutputRange
{
  bool known = false;
  float lowest = 0.0f;
  float highest = 0.0f;
};

/// Output arrays of region.voxelCount() values, x fastest; a null pointer skips it.
struct AmbientOcclusionOutput
{
  float* openness = nullptr;
  float* variance = nullptr; // intensity variance of the box (Ruiz et al. section 4.2)
  // Where not null: the openness's range, known when every value written was finite and
  // the method's pass kept it (the CPU's Chebyshev, Gaussian CDF and CDF Reconstruction,
  // on a processor with AVX2).
  OutputRange* opennessRange = nullptr;
};

struct BoxStatisticsOutput
{
  double* count = nullptr;
  double* mean = nullptr;
  double* variance = nullptr;
  double* minimum = nullptr;
  double* maximum = nullptr;
};

/// Result of a kernel call: ok, or why not (bad arguments, non-finite input, cancelled).
struct Status
{
  bool ok = true;
  bool aborted = false;
  std::string message;
  // Non-finite input values: how many, and the first one's index in the volume (x
  // fastest), so that a caller can name its voxel in its own coordinates.
  std::int64_t nonFiniteCount = 0;
  std::int64_t firstNonFinite = -1;
  bool outOfMemory = false;   // an allocation failed: smaller pieces may succeed
  bool deviceFailure = false; // the GPU could not do it (no device, a CUDA error): the CPU may

  static Status success() { return {}; }
  static Status failure(std::string why) { return { false, false, std::move(why) }; }
  static Status cancelled() { return { false, true, "cancelled" }; }
  static Status nonFinite(std::int64_t count, std::int64_t first);
  static Status device(std::string why)
  {
    Status status = failure(std::move(why));
    status.deviceFailure = true;
    return status;
  }
  /// An allocation failed: "not enough memory for <what>". Callable when no memory is
  /// left: where even that message cannot be had, it is "out of memory", short enough for
  /// std::string to hold without allocating.
  static Status noMemory(const char* what) noexcept
  {
    Status status;
    status.ok = false;
    status.outOfMemory = true;
    try
    {
      status.message = std::string("not enough memory for ") + what;
    }
    catch (const std::bad_alloc&)
    {
      status.message = "out of memory";
    }
    return status;
  }
  static Status noMemory(const std::string& what) noexcept { return noMemory(what.c_str()); }
};

/// Checks the volume, region and radius; returns the first problem found
/// (vao/Validation.h has the single checks).
Status validate(const VolumeView& volume, const Region& region, const Radius& radius);

/// Openness (and optionally the variance) of every voxel of the region.
Status computeAmbientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution = {});

/// Count, mean, variance, minimum and maximum over each voxel's clipped box.
Status computeBoxStatistics(const VolumeView& volume, const Region& region, const Radius& radius,
  const BoxStatisticsOutput& output, const Execution& execution = {});

/// The CPU threads a call with Execution::threads = `requested` uses: `requested` when
/// above 0, else the cores this process may run on divided by the MPI ranks on its node
/// (when a launcher says how many: OMPI_COMM_WORLD_LOCAL_SIZE, MPI_LOCALNRANKS,
/// MV2_COMM_WORLD_LOCAL_SIZE), at least 1.
int threadCount(int requested);

/// The library's worker pool for a caller's own loop (the VTK filters' per-point work):
/// body(begin, end) over chunks of [0, n) on threadCount(execution.threads) threads,
/// progress and cancellation polled on the calling thread between chunks. Returns false
/// when cancelled. body must be safe to run on several threads at once.
bool parallelRanges(std::int64_t n, const Execution& execution,
  const std::function<void(std::int64_t begin, std::int64_t end)>& body);

/// Number of voxels that are NaN or infinite (always 0 for integer types); the index of the
/// first one goes to firstIndex when not null. Runs on every core.
std::int64_t countNonFinite(const VolumeView& volume, std::int64_t* firstIndex = nullptr);

/// Smallest and largest finite value of the volume (one parallel pass).
std::array<double, 2> valueRange(const VolumeView& volume);

/// The voxels a volume's moment shift is the mean of: every max(1, n / 65536)-th voxel of
/// the data set (n voxels, x fastest). `volume` is the part of a data set of `wholeDims`
/// voxels that starts at `offset` in it; the sum and count are of the sampled voxels in
/// `region` of it. Over pieces that hold each voxel of the data set once, the sums give
/// the whole volume's shift (MomentBasis).
struct ShiftSamples
{
  double sum = 0.0;
  std::int64_t count = 0;
};
ShiftSamples momentShiftSamples(
  const VolumeView& volume, const Region& region, const Index3& offset, const Index3& wholeDims);

} // namespace vao
