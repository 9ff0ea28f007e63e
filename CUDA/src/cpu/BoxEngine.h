// The separable box statistics of every voxel: the streamed box sums (MomentPlanes.h) and,
// for CDF Reconstruction and the statistics, the box minimum and maximum, which are not
// invertible and take three van Herk passes (x and y per slice, then z per row); handed
// to consumers row by row.
#pragma once

#include "MomentPlanes.h"
#include "MomentRows.h"
#include "RowTranspose.h"
#include "SlidingExtremum.h"
#include "vao/Storage.h"

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

/// Box minimum and maximum of every region voxel: planes of the slices the region reads,
/// the region's own slices starting at `offset` (x fastest, region-sized planes).
template <class T>
struct BoxExtrema
{
  StorageArray<T> minimumPlanes; // uninitialised: the y pass writes every plane whole
  StorageArray<T> maximumPlanes;
  std::int64_t offset = 0;

  /// The box minima and maxima from region voxel `regionIndex` on.
  const T* minima(std::int64_t regionIndex) const { return this->minimumPlanes.data() + this->offset + regionIndex; }
  const T* maxima(std::int64_t regionIndex) const { return this->maximumPlanes.data() + this->offset + regionIndex; }
};

/// Rows of a slice whose x passes run together (one AVX2 vector of 16-bit values).
constexpr std::int64_t kExtremumRows = 16;

/// Three van Herk passes: x then y within each slice the region reads (into planes of
/// region width), then z along each region row, written back in place. Progress: slices,
/// then rows.
template <class T>
bool computeBoxExtrema(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const Execution& execution, BoxExtrema<T>& result)
{
  const Region& region = geometry.region;
  const std::int64_t nx = region.size[0];
  const std::int64_t plane = geometry.planeSize();
  const std::int64_t slices = geometry.zs.size();
  StorageArray<T>& planeMin = result.minimumPlanes;
  StorageArray<T>& planeMax = result.maximumPlanes;
  planeMin.resize(static_cast<std::size_t>(slices * plane));
  planeMax.resize(static_cast<std::size_t>(slices * plane));
  result.offset = (region.begin[2] - geometry.zs.lo) * plane;
  const int threads = resolveThreadCount(execution.threads);
  // Progress: the slices of the x/y passes, then the rows of the z pass.
  const std::int64_t work = slices + region.size[1];
  const bool planesDone = parallelFor(slices, threads, threads, stageExecution(execution, 0.0, double(slices) / work),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      const std::int64_t span = geometry.xs.size();
      const std::int64_t rows = geometry.ys.size();
      // The x pass takes kExtremumRows rows at once, transposed so that the rows are the
      // lanes: the recurrence runs along x on vectors instead of one value at a time.
      std::vector<T> lanes(static_cast<std::size_t>(span * kExtremumRows));
      std::vector<T> lanesMin(static_cast<std::size_t>(nx * kExtremumRows));
      std::vector<T> lanesMax(lanesMin.size());
      std::vector<T> xMin(static_cast<std::size_t>(rows * nx));
      std::vector<T> xMax(static_cast<std::size_t>(rows * nx));
      ExtremumScratch<T> scratch;
      const std::int64_t x0 = region.begin[0] - geometry.xs.lo;
      for (std::int64_t s = begin; s < end && !progress.stopped(); ++s)
      {
        const std::int64_t z = geometry.zs.lo + s;
        for (std::int64_t j0 = 0; j0 < rows; j0 += kExtremumRows)
        {
          const std::int64_t m = std::min(kExtremumRows, rows - j0);
          const T* src[kExtremumRows];
          T* minRows[kExtremumRows];
          T* maxRows[kExtremumRows];
          for (std::int64_t k = 0; k < m; ++k)
          {
            src[k] = volume.row(geometry.ys.lo + j0 + k, z) + geometry.xs.lo * volume.stride;
            minRows[k] = &xMin[(j0 + k) * nx];
            maxRows[k] = &xMax[(j0 + k) * nx];
          }
          rowsToLanes(src, m, volume.stride, span, lanes.data());
          slidingMinMax(lanes.data(), lanes.data(), span, m, geometry.radius.x, x0, nx, lanesMin.data(),
            lanesMax.data(), scratch);
          lanesToRows(lanesMin.data(), m, nx, minRows);
          lanesToRows(lanesMax.data(), m, nx, maxRows);
        }
        // y pass: whole rows are the lanes.
        const std::int64_t y0 = region.begin[1] - geometry.ys.lo;
        slidingMinMax(xMin.data(), xMax.data(), rows, nx, geometry.radius.y, y0, region.size[1],
          &planeMin[s * plane], &planeMax[s * plane], scratch);
        progress.advance();
      }
    });
  if (!planesDone)
  {
    return false;
  }

  return parallelFor(region.size[1], threads, threads, stageExecution(execution, double(slices) / work, 1.0),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      ExtremumScratch<T> scratch;
      const std::int64_t z0 = region.begin[2] - geometry.zs.lo;
      for (std::int64_t y = begin; y < end && !progress.stopped(); ++y)
      {
        // z pass: row y of every slice is a sequence of lane vectors, a plane apart; the
        // results go back in place (the pass reads all of its input first).
        T* rowMin = &planeMin[y * nx];
        T* rowMax = &planeMax[y * nx];
        slidingMinMax(rowMin, rowMax, slices, nx, geometry.radius.z, z0, region.size[2], rowMin + result.offset,
          rowMax + result.offset, scratch, plane, plane);
        progress.advance();
      }
    });
}

} // namespace detail
} // namespace vao

namespace vao
{
namespace detail
{

/// out[i] = double(in[i * stride]) for i < n: a row loop (CpuDispatch.h), so that rows of
/// contiguous 8- and 16-bit values widen on AVX2 vectors.
template <class T>
struct WidenRow
{
  static VAO_ALWAYS_INLINE void run(const T* __restrict in, std::int64_t stride, std::int64_t n,
    double* __restrict out)
  {
    if (stride == 1)
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = static_cast<double>(in[i]);
    else
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = static_cast<double>(in[i * stride]);
  }
};

/// The 64-bit box sums of a row of 32-bit ones (MomentPlanes' std::uint32_t sums hold the
/// bits of exact int32 sums): out[i] = int32(in[i]). Compiled for AVX2 too.
struct WidenSums
{
  static VAO_ALWAYS_INLINE void run(const std::uint32_t* __restrict in, std::int64_t n, std::int64_t* __restrict out)
  {
    for (std::int64_t i = 0; i < n; ++i)
      out[i] = static_cast<std::int32_t>(in[i]);
  }
};

/// One row of the region with the statistics of its voxels' neighbourhoods, as arrays
/// (x fastest), handed to a consumer: a row at a time lets the estimators run on vectors.
struct NeighbourhoodRow
{
  std::int64_t index = 0; // of the row's first voxel in the region, x fastest
  std::int64_t size = 0;  // voxels in the row
  const double* value = nullptr;    // the voxels' own values
  const double* count = nullptr;    // voxels in each clipped box
  const double* mean = nullptr;
  const double* variance = nullptr; // population variance, clamped at 0; null if not asked for
  const double* minimum = nullptr;  // null unless the extrema were asked for
  const double* maximum = nullptr;
  double roundingVariance = 0.0;    // as NeighbourhoodStats::roundingVariance
  // The boxes' exact integer sums (null for double sums), which Chebyshev and the Gaussian
  // CDF take directly (opennessFromExactSums): box i holds countX[i] * countYZ voxels.
  const std::int64_t* sum = nullptr;
  const std::int64_t* sumSquares = nullptr;
  const std::int64_t* countX = nullptr;
  std::int64_t countYZ = 0;

  NeighbourhoodStats stats(std::int64_t i) const
  {
    return { this->mean[i], this->variance ? this->variance[i] : 0.0, this->minimum ? this->minimum[i] : 0.0,
      this->maximum ? this->maximum[i] : 0.0, this->roundingVariance };
  }
};

/// What forEachNeighbourhoodRow hands over besides the sums: the box extrema (computed in
/// passes of their own), the means and variances, which exact integer sums can skip for
/// consumers that take the sums (NeighbourhoodRow::sum), and the voxels' own values.
/// Without `variance` the sums of squares are not formed (half the moments' work) and the
/// rows have the means alone.
struct RowContents
{
  bool extrema = false;
  bool moments = true;
  bool values = true;
  bool variance = true;
};

/// forEachNeighbourhoodRow on one band (band.region, a slab of rows of `whole`): voxel
/// indices are those of the whole region. `extrema` holds the band's extrema planes (kept
/// from band to band, so that their pages are not cleared anew for each).
template <class T, class Visit>
bool visitBand(const TypedVolume<T>& volume, const BoxGeometry& band, const Region& whole,
  const MomentScale& scale, RowContents contents, const Execution& execution, BoxExtrema<T>& extrema,
  Visit&& visit)
{
  const bool withExtrema = contents.extrema;
  const Region& region = band.region;
  const double split = withExtrema ? 0.5 : 0.0;
  if (withExtrema && !computeBoxExtrema(volume, band, stageExecution(execution, 0.0, split), extrema))
  {
    return false;
  }
  const auto countX = band.windowCounts(0);
  const auto countY = band.windowCounts(1);
  const std::int64_t nx = region.size[0], ny = region.size[1];
  const std::int64_t wholePlane = whole.size[0] * whole.size[1];
  const std::int64_t firstRow = region.begin[1] - whole.begin[1];
  const auto consume = [&](const auto& slice) {
    const std::int64_t bandBase = (slice.z - region.begin[2]) * nx * ny;
    const std::int64_t base = (slice.z - whole.begin[2]) * wholePlane + firstRow * nx;
    const auto n = static_cast<std::size_t>(nx);
    std::vector<double> value(n), count(n), mean(n), variance(n), minimum, maximum;
    constexpr bool narrow = std::is_same<std::decay_t<decltype(*slice.sum)>, std::uint32_t>::value;
    std::vector<std::int64_t> sums(narrow ? n : 0); // the row's sums widened
    if (withExtrema)
    {
      minimum.resize(n);
      maximum.resize(n);
    }
    const SimdTier simd = cpuSimdTier();
    NeighbourhoodRow out;
    out.size = nx;
    out.value = value.data();
    out.count = count.data();
    out.mean = mean.data();
    out.variance = contents.variance ? variance.data() : nullptr;
    out.minimum = withExtrema ? minimum.data() : nullptr;
    out.maximum = withExtrema ? maximum.data() : nullptr;
    out.roundingVariance = slice.roundingVariance;
    for (std::int64_t j = 0; j < ny; ++j)
    {
      const T* row = volume.row(region.begin[1] + j, slice.z) + region.begin[0] * volume.stride;
      const std::int64_t countYZ = countY[j] * slice.countZ;
      if (contents.values)
        runRows<WidenRow<T>>(simd, row, volume.stride, nx, value.data());
      if constexpr (MomentTraits<T>::exactInteger)
      {
        if constexpr (narrow)
        {
          runRows<WidenSums>(simd, slice.sum + j * nx, nx, sums.data());
          out.sum = sums.data();
        }
        else
          out.sum = slice.sum + j * nx;
        out.sumSquares = slice.sumSquares ? slice.sumSquares + j * nx : nullptr;
        out.countX = countX.data();
        out.countYZ = countYZ;
        if (contents.moments) // double sums below always give them
          meanVarianceRowExact(out.sum, out.sumSquares, countX.data(), countYZ, nx, count.data(), mean.data(),
            out.sumSquares ? variance.data() : nullptr);
      }
      else
      {
        for (std::int64_t i = 0; i < nx; ++i)
        {
          const std::int64_t p = j * nx + i;
          const std::int64_t c = countX[i] * countYZ;
          count[i] = static_cast<double>(c);
          // Without the squares the mean comes out the same and the variance is dropped.
          meanVarianceFromSums(slice.sum[p], slice.sumSquares ? slice.sumSquares[p] : 0.0, c, slice.shift,
            mean[i], variance[i]);
        }
      }
      if (withExtrema)
      {
        runRows<WidenRow<T>>(simd, extrema.minima(bandBase + j * nx), std::int64_t(1), nx, minimum.data());
        runRows<WidenRow<T>>(simd, extrema.maxima(bandBase + j * nx), std::int64_t(1), nx, maximum.data());
      }
      out.index = base + j * nx;
      visit(static_cast<const NeighbourhoodRow&>(out));
    }
  };
  const Execution stage = stageExecution(execution, split, 1.0);
  if constexpr (MomentTraits<T>::exactInteger)
    if (linearSumsFit32<T>(band))
      return streamMoments<T, std::uint32_t>(volume, band, scale, contents.variance, stage, consume);
  return streamMoments<T, typename MomentTraits<T>::Accumulator>(
    volume, band, scale, contents.variance, stage, consume);
}

/// Rows of region per band when the extrema are needed: a band's extrema planes hold
/// 2 x (slices read) x rows x width values, so bands of 1/10 of the volume's rows keep
/// them at 1/5 of the input's size (CDF Reconstruction's working memory stays under 25%
/// of the input: 21.7% on the 512x512x209 CT head). Each band re-reads R rows above and
/// below it in the x and y passes, so the fewer bands the fewer rows read: at R = 10 the
/// CT head's 512 rows read 732 rows in 11 bands where they read 832 in 16 at 1/16 of the
/// rows. Bands of at least 2R + 1 rows keep that price under 2x.
inline std::int64_t extremaBandRows(const BoxGeometry& geometry)
{
  return std::max<std::int64_t>({ 8, geometry.dims[1] / 10, 2 * std::int64_t(geometry.radius.y) + 1 });
}

/// The separable statistics of every region voxel, handed to visit(NeighbourhoodRow) row
/// by row, slice by slice on worker threads: the streamed moments, after the extrema passes when
/// withExtrema. With the extrema the region goes band by band of rows (extremaBandRows),
/// each band's extrema first, then its moments. Returns false when cancelled.
template <class T, class Visit>
bool forEachNeighbourhoodRow(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const MomentScale& scale, RowContents contents, const Execution& execution, Visit&& visit)
{
  const bool withExtrema = contents.extrema;
  const Region& region = geometry.region;
  const std::int64_t ny = region.size[1];
  // As many bands as rows of extremaBandRows take, of equal rows: a short last band
  // would read its 2R halo rows for few rows of its own.
  const std::int64_t most = withExtrema ? std::min(ny, extremaBandRows(geometry)) : ny;
  const std::int64_t bandRows = (ny + (ny + most - 1) / most - 1) / ((ny + most - 1) / most);
  const std::int64_t bands = (ny + bandRows - 1) / bandRows;
  BoxExtrema<T> extrema;
  for (std::int64_t b = 0; b < bands; ++b)
  {
    Region band = region;
    band.begin[1] = region.begin[1] + b * bandRows;
    band.size[1] = std::min(bandRows, ny - b * bandRows);
    const Execution stage = stageExecution(execution, double(b) / bands, double(b + 1) / bands);
    if (!visitBand(
          volume, BoxGeometry(geometry.dims, band, geometry.radius), region, scale, contents, stage, extrema, visit))
    {
      return false;
    }
  }
  return true;
}

} // namespace detail
} // namespace vao
