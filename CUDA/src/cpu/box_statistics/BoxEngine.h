// The separable box statistics of every voxel: the streamed box sums (MomentPlanes.h) and,
// for CDF Reconstruction and the statistics, the box minimum and maximum (BoxExtrema.h);
// handed to consumers row by row.
#pragma once

#include "cpu/box_statistics/BoxExtrema.h"
#include "cpu/box_statistics/MomentPlanes.h"
#include "cpu/box_statistics/MomentRows.h"

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

/// out[i] = double(in[i * stride]) for i < n: a row loop (CpuDispatch.h), so that rows of
/// contiguous 8- and 16-bit values widen on AVX2 vectors.
template <class T>
struct WidenRow
{
  static VAO_ALWAYS_INLINE void run(
    const T* __restrict in, std::int64_t stride, std::int64_t n, double* __restrict out)
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
  static VAO_ALWAYS_INLINE void run(
    const std::uint32_t* __restrict in, std::int64_t n, std::int64_t* __restrict out)
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
  const void* value = nullptr;   // the voxels' own, contiguous; null unless RowContents::values
  const void* minimum = nullptr; // null unless RowContents::extrema
  const void* maximum = nullptr;
  const std::int32_t* sum = nullptr; // null: the row is not raw
};

/// One row of the region with the statistics of its voxels' neighbourhoods, as arrays
/// (x fastest), handed to a consumer: a row at a time lets the estimators run on vectors.
struct NeighbourhoodRow
{
  std::int64_t index = 0;        // of the row's first voxel in the region, x fastest
  std::int64_t size = 0;         // voxels in the row
  const double* value = nullptr; // the voxels' own values
  const double* count = nullptr; // voxels in each clipped box
  const double* mean = nullptr;
  const double* variance = nullptr; // population variance, clamped at 0; null if not asked for
  const double* minimum = nullptr;  // null unless the extrema were asked for
  const double* maximum = nullptr;
  double roundingVariance = 0.0; // as NeighbourhoodStats::roundingVariance
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
    return { this->mean[i], this->variance ? this->variance[i] : 0.0,
      this->minimum ? this->minimum[i] : 0.0, this->maximum ? this->maximum[i] : 0.0,
      this->roundingVariance };
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

/// What the workers of one band of visitBand share: the band (a slab of rows of `whole`),
/// its extrema planes, the clipped box sizes along x and y, and where its rows lie in the
/// whole region (NeighbourhoodRow::index counts voxels of the whole region).
template <class T>
struct BandRows
{
  const TypedVolume<T>& volume;
  const BoxGeometry& band;
  const Region& whole;
  RowContents contents;
  const BoxExtrema<T>& extrema;
  std::vector<std::int64_t> countX; // voxels along x of each row voxel's clipped box
  std::vector<std::int64_t> countY; // voxels along y, per band row
  std::int64_t wholePlane;          // voxels of a slice of the whole region
  std::int64_t firstRow;            // the band's first row in the whole region
};

/// visitBand's second pass, one per worker: each slice's box sums (streamMoments) and, with
/// the extrema, its x pass (SliceExtrema) become NeighbourhoodRows handed to visit row by
/// row. The row buffers are the worker's, made once for its chunk of slices, not per slice.
template <class T, class Visit>
class BandRowConsumer
{
public:
  BandRowConsumer(const BandRows<T>& rows, Visit& visit)
    : Rows(rows)
    , VisitRow(visit)
    , Value(width(rows))
    , Count(width(rows))
    , Mean(width(rows))
    , Variance(width(rows))
    , Minimum(rows.contents.extrema ? width(rows) : 0)
    , Maximum(rows.contents.extrema ? width(rows) : 0)
    , Sums(width(rows))
  {
  }

  /// Slice slice.z of the band: the x pass of its extrema first (the rows read them), then
  /// its rows in order, raw where the consumer takes raw rows (RowContents::raw).
  template <class Lin>
  void operator()(const MomentSlice<T, Lin>& slice)
  {
    const BandRows<T>& rows = this->Rows;
    const Region& region = rows.band.region;
    const std::int64_t nx = region.size[0], ny = region.size[1];
    const std::int64_t base =
      (slice.z - rows.whole.begin[2]) * rows.wholePlane + rows.firstRow * nx;
    constexpr bool narrow = std::is_same<Lin, std::uint32_t>::value;
    if (rows.contents.extrema)
      this->Extrema.compute(rows.extrema, rows.band, slice.z - region.begin[2]);
    const SimdTier simd = cpuSimdTier();
    NeighbourhoodRow out = this->rowBuffers(slice.roundingVariance);
    const bool raw = narrow && kSixteenBit && rows.contents.raw && rows.volume.stride == 1;
    if (raw)
    {
      out.value = out.count = out.mean = out.variance = out.minimum = out.maximum = nullptr;
      out.raw.type = std::is_signed<T>::value ? ScalarType::Int16 : ScalarType::UInt16;
    }
    for (std::int64_t j = 0; j < ny; ++j)
    {
      const T* row =
        rows.volume.row(region.begin[1] + j, slice.z) + region.begin[0] * rows.volume.stride;
      const std::int64_t countYZ = rows.countY[j] * slice.countZ;
      out.index = base + j * nx;
      if constexpr (narrow && kSixteenBit)
      {
        if (raw)
        {
          this->rawRow(slice, j, row, countYZ, out);
          continue;
        }
      }
      this->statisticsRow(slice, j, row, countYZ, simd, out);
    }
  }

private:
  static constexpr bool kSixteenBit =
    std::is_same<T, std::int16_t>::value || std::is_same<T, std::uint16_t>::value;

  static std::size_t width(const BandRows<T>& rows)
  {
    return static_cast<std::size_t>(rows.band.region.size[0]);
  }

  /// The row every slice hands over, pointing at this worker's buffers; only what was
  /// asked for is set (RowContents).
  NeighbourhoodRow rowBuffers(double roundingVariance)
  {
    const bool withExtrema = this->Rows.contents.extrema;
    NeighbourhoodRow out;
    out.size = this->Rows.band.region.size[0];
    out.value = this->Value.data();
    out.count = this->Count.data();
    out.mean = this->Mean.data();
    out.variance = this->Rows.contents.variance ? this->Variance.data() : nullptr;
    out.minimum = withExtrema ? this->Minimum.data() : nullptr;
    out.maximum = withExtrema ? this->Maximum.data() : nullptr;
    out.roundingVariance = roundingVariance;
    return out;
  }

  /// Row j of 16-bit voxels as the passes leave it (RawRow): the voxels, the 32-bit sums
  /// and the extrema, not widened, for a consumer that widens them on its own lanes.
  template <class Lin>
  VAO_ALWAYS_INLINE void rawRow(const MomentSlice<T, Lin>& slice, std::int64_t j, const T* row,
    std::int64_t countYZ, NeighbourhoodRow& out)
  {
    const std::int64_t nx = out.size;
    const bool withExtrema = this->Rows.contents.extrema;
    out.raw.value = this->Rows.contents.values ? row : nullptr;
    out.raw.minimum = withExtrema ? this->Extrema.minima(j) : nullptr;
    out.raw.maximum = withExtrema ? this->Extrema.maxima(j) : nullptr;
    // The 32-bit sums hold the bits of exact int32 sums (MomentPlanes.h).
    out.raw.sum = reinterpret_cast<const std::int32_t*>(slice.sum + j * nx);
    out.sumSquares = slice.sumSquares ? slice.sumSquares + j * nx : nullptr;
    out.countX = this->Rows.countX.data();
    out.countYZ = countYZ;
    this->VisitRow(static_cast<const NeighbourhoodRow&>(out));
  }

  /// Row j widened to doubles: the voxels' values, the boxes' counts, means and variances
  /// (from exact integer sums, which are handed over too, or from double sums), and the
  /// extrema of the slice's x pass.
  template <class Lin>
  VAO_ALWAYS_INLINE void statisticsRow(const MomentSlice<T, Lin>& slice, std::int64_t j,
    const T* row, std::int64_t countYZ, SimdTier simd, NeighbourhoodRow& out)
  {
    const std::int64_t nx = out.size;
    const std::vector<std::int64_t>& countX = this->Rows.countX;
    if (this->Rows.contents.values)
      runRows<WidenRow<T>>(simd, row, this->Rows.volume.stride, nx, this->Value.data());
    if constexpr (MomentTraits<T>::exactInteger)
    {
      if constexpr (std::is_same<Lin, std::uint32_t>::value)
      {
        runRows<WidenSums>(simd, slice.sum + j * nx, nx, this->Sums.data());
        out.sum = this->Sums.data();
      }
      else
        out.sum = slice.sum + j * nx;
      out.sumSquares = slice.sumSquares ? slice.sumSquares + j * nx : nullptr;
      out.countX = countX.data();
      out.countYZ = countYZ;
      if (this->Rows.contents.moments) // double sums below always give them
        meanVarianceRowExact(out.sum, out.sumSquares, countX.data(), countYZ, nx,
          this->Count.data(), this->Mean.data(), out.sumSquares ? this->Variance.data() : nullptr);
    }
    else
    {
      for (std::int64_t i = 0; i < nx; ++i)
      {
        const std::int64_t p = j * nx + i;
        const std::int64_t c = countX[i] * countYZ;
        this->Count[i] = static_cast<double>(c);
        // Without the squares the mean comes out the same and the variance is dropped.
        meanVarianceFromSums(slice.sum[p], slice.sumSquares ? slice.sumSquares[p] : 0.0, c,
          slice.shift, this->Mean[i], this->Variance[i]);
      }
    }
    if (this->Rows.contents.extrema)
    {
      runRows<WidenRow<T>>(
        simd, this->Extrema.minima(j), std::int64_t(1), nx, this->Minimum.data());
      runRows<WidenRow<T>>(
        simd, this->Extrema.maxima(j), std::int64_t(1), nx, this->Maximum.data());
    }
    this->VisitRow(static_cast<const NeighbourhoodRow&>(out));
  }

  const BandRows<T>& Rows;
  Visit& VisitRow;
  std::vector<double> Value, Count, Mean, Variance, Minimum, Maximum;
  std::vector<std::int64_t> Sums; // a row's 32-bit sums widened
  SliceExtrema<T> Extrema;
};

/// forEachNeighbourhoodRow on one band (band.region, a slab of rows of `whole`), in two
/// passes: the band's box extrema first (computeBoxExtrema, when asked for: their y and z
/// passes need every slice the band reads before any row can be handed over), then the
/// streamed moments, whose slices the workers' BandRowConsumers turn into rows. Voxel
/// indices are those of the whole region. `extrema` holds the band's extrema planes (kept
/// from band to band, so that their pages are not cleared anew for each).
template <class T, class Visit>
bool visitBand(const TypedVolume<T>& volume, const BoxGeometry& band, const Region& whole,
  const MomentScale& scale, RowContents contents, const Execution& execution,
  BoxExtrema<T>& extrema, Visit&& visit)
{
  const bool withExtrema = contents.extrema;
  const Region& region = band.region;
  const double split = withExtrema ? 0.5 : 0.0;
  if (withExtrema &&
    !computeBoxExtrema(volume, band, stageExecution(execution, 0.0, split), extrema))
  {
    return false;
  }
  const BandRows<T> rows{ volume, band, whole, contents, extrema, band.windowCounts(0),
    band.windowCounts(1), whole.size[0] * whole.size[1], region.begin[1] - whole.begin[1] };
  using Consumer = BandRowConsumer<T, std::remove_reference_t<Visit>>;
  const auto makeConsumer = [&] { return Consumer(rows, visit); };
  const Execution stage = stageExecution(execution, split, 1.0);
  if constexpr (MomentTraits<T>::exactInteger)
    if (linearSumsFit32<T>(band))
      return streamMoments<T, std::uint32_t>(
        volume, band, scale, contents.variance, stage, makeConsumer);
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
  return std::max<std::int64_t>(
    { 8, geometry.dims[1] / 10, 2 * std::int64_t(geometry.radius.y) + 1 });
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
    if (!visitBand(volume, BoxGeometry(geometry.dims, band, geometry.radius), region, scale,
          contents, stage, extrema, visit))
    {
      return false;
    }
  }
  return true;
}

} // namespace detail
} // namespace vao
