// The separable box statistics of every voxel: the streamed box sums (MomentPlanes.h) and,
// for CDF Reconstruction and the statistics, the box minimum and maximum, which are not
// invertible and take three van Herk passes (y per slice, z per row, then x per slice as
// its rows are consumed); handed to consumers row by row.
#pragma once

#include "cpu/box_statistics/MomentPlanes.h"
#include "cpu/box_statistics/MomentRows.h"
#include "cpu/box_statistics/RowTranspose.h"
#include "cpu/box_statistics/SlidingExtremum.h"
#include "vao/Storage.h"

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

/// Box minimum and maximum of every region voxel, in two steps. computeBoxExtrema runs
/// the y pass on every slice the region reads, straight from the volume, and then the z
/// pass along each row, into planes of the region's rows by the x span its boxes read;
/// SliceExtrema runs the x pass of one region slice as its rows are consumed. The x pass
/// comes last so that it takes the region's rows alone: a band of rows (forEachNeighbourhoodRow)
/// reads R rows above and below it, which an x pass first would also take. Minima and
/// maxima are exact in any order of the passes.
template <class T>
struct BoxExtrema
{
  StorageArray<T> minimumPlanes; // uninitialised: the y pass writes every plane whole
  StorageArray<T> maximumPlanes;
  std::int64_t offset = 0; // where the region's first slice starts
  std::int64_t width = 0;  // values a plane row holds: the x span the boxes read
  std::int64_t rows = 0;   // rows a plane holds: the region's

  /// Row j of region slice k, after the y and z passes.
  const T* minimumRow(std::int64_t k, std::int64_t j) const
  {
    return this->minimumPlanes.data() + this->offset + (k * this->rows + j) * this->width;
  }
  const T* maximumRow(std::int64_t k, std::int64_t j) const
  {
    return this->maximumPlanes.data() + this->offset + (k * this->rows + j) * this->width;
  }
};

/// Rows of a slice whose x passes run together (one AVX2 vector of 16-bit values).
constexpr std::int64_t kExtremumRows = 16;

/// The y pass of every slice the region reads, then the z pass along each region row,
/// written back in place (BoxExtrema). Progress: slices, then rows.
template <class T>
bool computeBoxExtrema(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const Execution& execution, BoxExtrema<T>& result)
{
  const Region& region = geometry.region;
  const std::int64_t span = geometry.xs.size();
  const std::int64_t rows = region.size[1];
  const std::int64_t plane = span * rows;
  const std::int64_t slices = geometry.zs.size();
  StorageArray<T>& planeMin = result.minimumPlanes;
  StorageArray<T>& planeMax = result.maximumPlanes;
  planeMin.resize(static_cast<std::size_t>(slices * plane));
  planeMax.resize(static_cast<std::size_t>(slices * plane));
  result.offset = (region.begin[2] - geometry.zs.lo) * plane;
  result.width = span;
  result.rows = rows;
  const int threads = resolveThreadCount(execution.threads);
  // Progress: the slices of the y pass, then the rows of the z pass.
  const std::int64_t work = slices + rows;
  const bool planesDone = parallelFor(slices, threads, threads, stageExecution(execution, 0.0, double(slices) / work),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      const std::int64_t read = geometry.ys.size();
      // Interleaved voxels (one component of several) are gathered first: the pass takes
      // each row's span as contiguous lanes.
      std::vector<T> gathered(volume.stride == 1 ? 0 : static_cast<std::size_t>(read * span));
      ExtremumScratch<T> scratch;
      for (std::int64_t s = begin; s < end && !progress.stopped(); ++s)
      {
        const std::int64_t z = geometry.zs.lo + s;
        const T* first = volume.row(geometry.ys.lo, z) + geometry.xs.lo * volume.stride;
        std::int64_t rowStride = volume.dims[0]; // values from one row's first to the next's
        if (volume.stride != 1)
        {
          for (std::int64_t j = 0; j < read; ++j)
          {
            const T* row = volume.row(geometry.ys.lo + j, z) + geometry.xs.lo * volume.stride;
            for (std::int64_t i = 0; i < span; ++i)
              gathered[static_cast<std::size_t>(j * span + i)] = row[i * volume.stride];
          }
          first = gathered.data();
          rowStride = span;
        }
        // y pass: the rows are the sequence, their x spans the lanes.
        slidingMinMax(first, first, read, span, geometry.radius.y, region.begin[1] - geometry.ys.lo, rows,
          &planeMin[s * plane], &planeMax[s * plane], scratch, rowStride);
        progress.advance();
      }
    });
  if (!planesDone)
  {
    return false;
  }

  return parallelFor(rows, threads, threads, stageExecution(execution, double(slices) / work, 1.0),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      ExtremumScratch<T> scratch;
      const std::int64_t z0 = region.begin[2] - geometry.zs.lo;
      for (std::int64_t y = begin; y < end && !progress.stopped(); ++y)
      {
        // z pass: row y of every slice is a sequence of lane vectors, a plane apart; the
        // results go back in place (the pass reads all of its input first).
        T* rowMin = &planeMin[y * span];
        T* rowMax = &planeMax[y * span];
        slidingMinMax(rowMin, rowMax, slices, span, geometry.radius.z, z0, region.size[2], rowMin + result.offset,
          rowMax + result.offset, scratch, plane, plane);
        progress.advance();
      }
    });
}

/// The x pass of one region slice (BoxExtrema's y and z passes done): the box minima and
/// maxima of its voxels, a row of the region's width per region row. Each worker of
/// visitBand keeps one for the slices it consumes, so its buffers are made once.
template <class T>
class SliceExtrema
{
public:
  const T* minima(std::int64_t j) const { return this->Minima.data() + j * this->Width; }
  const T* maxima(std::int64_t j) const { return this->Maxima.data() + j * this->Width; }

  /// Region slice k: kExtremumRows rows at once, transposed so that the rows are the
  /// lanes and the recurrence runs along x on vectors.
  void compute(const BoxExtrema<T>& extrema, const BoxGeometry& geometry, std::int64_t k)
  {
    const Region& region = geometry.region;
    const std::int64_t nx = region.size[0], span = extrema.width;
    this->Width = nx;
    this->Minima.resize(static_cast<std::size_t>(extrema.rows * nx));
    this->Maxima.resize(this->Minima.size());
    this->LanesMin.resize(static_cast<std::size_t>(span * kExtremumRows));
    this->LanesMax.resize(this->LanesMin.size());
    this->OutMin.resize(static_cast<std::size_t>(nx * kExtremumRows));
    this->OutMax.resize(this->OutMin.size());
    // A last group of fewer rows runs as a whole one where the transposes take blocks of
    // 16 rows (else they and the pass would go value by value): its spare lanes repeat
    // the last row and their results go to a row that is not kept.
    const bool padded = transposesInBlocks<T>();
    this->Spare.resize(static_cast<std::size_t>(padded ? 2 * nx : 0));
    const std::int64_t x0 = region.begin[0] - geometry.xs.lo;
    for (std::int64_t j0 = 0; j0 < extrema.rows; j0 += kExtremumRows)
    {
      const std::int64_t m = std::min(kExtremumRows, extrema.rows - j0);
      const std::int64_t lanes = padded ? kExtremumRows : m;
      const T* inMin[kExtremumRows];
      const T* inMax[kExtremumRows];
      T* minRows[kExtremumRows];
      T* maxRows[kExtremumRows];
      for (std::int64_t r = 0; r < lanes; ++r)
      {
        const std::int64_t j = j0 + std::min(r, m - 1);
        inMin[r] = extrema.minimumRow(k, j);
        inMax[r] = extrema.maximumRow(k, j);
        minRows[r] = r < m ? &this->Minima[static_cast<std::size_t>(j * nx)] : this->Spare.data();
        maxRows[r] = r < m ? &this->Maxima[static_cast<std::size_t>(j * nx)] : this->Spare.data() + nx;
      }
      rowsToLanes(inMin, lanes, 1, span, this->LanesMin.data());
      rowsToLanes(inMax, lanes, 1, span, this->LanesMax.data());
      slidingMinMax(this->LanesMin.data(), this->LanesMax.data(), span, lanes, geometry.radius.x, x0, nx,
        this->OutMin.data(), this->OutMax.data(), this->Scratch);
      lanesToRows(this->OutMin.data(), lanes, nx, minRows);
      lanesToRows(this->OutMax.data(), lanes, nx, maxRows);
    }
  }

private:
  std::int64_t Width = 0;
  std::vector<T> Minima, Maxima;                     // rows of the region's width
  std::vector<T> LanesMin, LanesMax, OutMin, OutMax; // the transposed rows, in and out
  std::vector<T> Spare;                              // results of padding lanes, not kept
  ExtremumScratch<T> Scratch;
};

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

/// A row of 16-bit voxels (Int16 or UInt16) with its exact 32-bit box sums (and box extrema)
/// as the passes leave them (RowContents::raw): the estimators' lanes widen these
/// themselves (opennessRow), where widening them into rows of doubles first, and CDF
/// Reconstruction's means in a pass of their own, cost a sixth of its time.
struct RawRow
{
  ScalarType type = ScalarType::Int16;
  const void* value = nullptr; // the voxels' own, contiguous; null unless RowContents::values
  const void* minimum = nullptr; // null unless RowContents::extrema
  const void* maximum = nullptr;
  const std::int32_t* sum = nullptr; // null: the row is not raw
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
  // Where raw.sum is set, the row holds raw, sumSquares, countX and countYZ alone: value,
  // count, mean, variance, minimum, maximum and sum are null.
  RawRow raw;

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
  // Rows of 16-bit voxels with 32-bit sums may come raw (NeighbourhoodRow::raw), for a
  // consumer that reads raw rows (opennessRow) and asks for no other output.
  bool raw = false;
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
  // A worker's row buffers and x pass, made once for its chunk of slices.
  struct Buffers
  {
    Buffers(std::size_t n, bool extrema)
      : value(n)
      , count(n)
      , mean(n)
      , variance(n)
      , minimum(extrema ? n : 0)
      , maximum(extrema ? n : 0)
      , sums(n)
    {
    }
    std::vector<double> value, count, mean, variance, minimum, maximum;
    std::vector<std::int64_t> sums; // a row's 32-bit sums widened
    SliceExtrema<T> sliceExtrema;
  };
  const auto consumeSlice = [&](const auto& slice, Buffers& buffers) {
    const std::int64_t base = (slice.z - whole.begin[2]) * wholePlane + firstRow * nx;
    std::vector<double>&value = buffers.value, &count = buffers.count, &mean = buffers.mean,
                       &variance = buffers.variance, &minimum = buffers.minimum, &maximum = buffers.maximum;
    std::vector<std::int64_t>& sums = buffers.sums;
    constexpr bool narrow = std::is_same<std::decay_t<decltype(*slice.sum)>, std::uint32_t>::value;
    SliceExtrema<T>& sliceExtrema = buffers.sliceExtrema;
    if (withExtrema)
      sliceExtrema.compute(extrema, band, slice.z - region.begin[2]);
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
    constexpr bool sixteenBit = std::is_same<T, std::int16_t>::value || std::is_same<T, std::uint16_t>::value;
    const bool raw = narrow && sixteenBit && contents.raw && volume.stride == 1;
    if (raw)
    {
      out.value = out.count = out.mean = out.variance = out.minimum = out.maximum = nullptr;
      out.raw.type = std::is_signed<T>::value ? ScalarType::Int16 : ScalarType::UInt16;
    }
    for (std::int64_t j = 0; j < ny; ++j)
    {
      const T* row = volume.row(region.begin[1] + j, slice.z) + region.begin[0] * volume.stride;
      const std::int64_t countYZ = countY[j] * slice.countZ;
      out.index = base + j * nx;
      if constexpr (narrow && sixteenBit)
      {
        if (raw)
        {
          out.raw.value = contents.values ? row : nullptr;
          out.raw.minimum = withExtrema ? sliceExtrema.minima(j) : nullptr;
          out.raw.maximum = withExtrema ? sliceExtrema.maxima(j) : nullptr;
          // The 32-bit sums hold the bits of exact int32 sums (MomentPlanes.h).
          out.raw.sum = reinterpret_cast<const std::int32_t*>(slice.sum + j * nx);
          out.sumSquares = slice.sumSquares ? slice.sumSquares + j * nx : nullptr;
          out.countX = countX.data();
          out.countYZ = countYZ;
          visit(static_cast<const NeighbourhoodRow&>(out));
          continue;
        }
      }
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
        runRows<WidenRow<T>>(simd, sliceExtrema.minima(j), std::int64_t(1), nx, minimum.data());
        runRows<WidenRow<T>>(simd, sliceExtrema.maxima(j), std::int64_t(1), nx, maximum.data());
      }
      visit(static_cast<const NeighbourhoodRow&>(out));
    }
  };
  const auto makeConsumer = [&] {
    return [&consumeSlice, buffers = Buffers(static_cast<std::size_t>(nx), withExtrema)](
             const auto& slice) mutable { consumeSlice(slice, buffers); };
  };
  const Execution stage = stageExecution(execution, split, 1.0);
  if constexpr (MomentTraits<T>::exactInteger)
    if (linearSumsFit32<T>(band))
      return streamMoments<T, std::uint32_t>(volume, band, scale, contents.variance, stage, makeConsumer);
  return streamMoments<T, typename MomentTraits<T>::Accumulator>(
    volume, band, scale, contents.variance, stage, makeConsumer);
}

/// Rows of region per band when the extrema are needed: a band's extrema planes hold
/// 2 x (slices read) x rows x (the x span the boxes read, at most width + 2R) values, so
/// bands of 1/10 of the volume's rows keep them at about 1/5 of the input's size (CDF
/// Reconstruction's working memory stays under 25% of the input). Each band re-reads R
/// rows above and below it in its y pass, so the fewer bands the fewer rows read: at
/// R = 10 the CT head's 512 rows read 732 rows in 11 bands where they read 832 in 16 at
/// 1/16 of the rows. Bands of at least 2R + 1 rows keep that price under 2x.
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
  const std::int64_t shares = (ny + most - 1) / most;
  const std::int64_t bandRows = (ny + shares - 1) / shares;
  const std::int64_t bands = (ny + bandRows - 1) / bandRows; // shares, or fewer: none empty
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
