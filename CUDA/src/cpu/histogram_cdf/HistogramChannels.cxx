// Histogram CDF on the CPU: the box histogram of every voxel over the thresholds' bins.
//
// A voxel falls in bin b = thresholdIndex(v) (v <= t_b, above t_(b-1)). The box counts of
// all bins are separable box sums of one-hot indicator volumes, computed together as
// vectors of `lanes` small unsigned integers per pixel, held cumulatively (lane c: bin c or
// below; HistogramLanes.h). The work goes tile by tile (a block of output columns and a
// z-range, planTiles in HistogramTiles.h), which keeps a tile's state in the processor's
// cache and the extra memory far below the input's size:
//  - Window: the counts of the 2 Rz + 1 slices around z, per pixel of the tile grown by
//    the radius, in 8-bit lanes where 2 Rz + 1 fits. Moving to the next slice adds one
//    voxel's bin and removes one: O(1) vector work, none for a row whose entering and
//    leaving voxels share their bins. Each voxel's bin is found once per tile, when its
//    slice enters, and kept in a ring of the 2 Rz + 2 slices' bins (with each row's lowest
//    and highest bin) for the slice leaving and for the query.
//  - Columns: the window summed over the 2 Ry + 1 rows around the output row, per pixel of
//    the row (a running sum that moves one row down by the entering and leaving rows).
//  - The x window over the columns (a running histogram along the output row) gives each
//    output voxel's 3-D box histogram, from which its query takes F just below and at the
//    query's bin: two lanes.
//  - A row whose boxes all hold one bin (the background of a segmented or generated
//    volume, the padding around a scan) skips the columns and the x window: its counts
//    follow from the bin and each box's voxel count, as the Gaussian CDF's flat boxes do.
// Counts never exceed the box's voxel count; lanes are 16 bits when that fits and the
// intermediate sums may wrap (unsigned arithmetic is modular, and the final counts are
// below 2^16), else 32 bits.
#include "cpu/histogram_cdf/HistogramChannels.h"

#include "cpu/histogram_cdf/HistogramBins.h"
#include "cpu/histogram_cdf/HistogramLanes.h"
#include "cpu/histogram_cdf/HistogramTiles.h"

#include "VolumeAccess.h"
#include "cpu/common/ConcurrentRange.h"
#include "cpu/common/Parallel.h"
#include "cpu/simd/CpuDispatch.h"

#include "vao/Estimators.h"

#include <algorithm>
#include <limits>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{
namespace
{

struct HistogramJob
{
  TilePlan plan;
  const Region& region;
  const Radius& radius;
  const std::vector<double>& thresholds;
  const HistogramQuery& query;
  float* openness;
  SimdTier simd;
  ConcurrentRange* range; // keeps the range of what is written, or null
};

/// One tile's state, reused for the tiles of one worker: counts in lanes of L, the window's
/// in W (8-bit where they fit), `Fixed` lanes (0: as many as the bins need).
template <class T, class L, class W, int Fixed>
class TileHistograms
{
  /// A voxel's bin in the ring (binBytes).
  using B = typename std::conditional<Fixed == 64, std::uint8_t, std::uint16_t>::type;
  template <int VectorBytes>
  using RowQueryOf = RowQuery<L, Fixed, VectorBytes>;

public:
  TileHistograms(const TypedVolume<T>& volume, const HistogramJob& job, const BinOf<T>& bin)
    : Volume(volume)
    , Job(job)
    , Bin(bin)
    , Bins(static_cast<int>(job.thresholds.size()))
    , Lanes(laneCount(Bins))
  {
    const std::int64_t tile = job.plan.sideX; // outputs of a row
    const std::int64_t span = job.plan.spanX; // pixels of a row
    this->RingSlices = ringSlices(job.radius);
    this->SlicePixels = span * job.plan.spanY;
    this->SliceBins.resize(static_cast<std::size_t>(this->RingSlices * this->SlicePixels));
    this->RowLow.resize(static_cast<std::size_t>(this->RingSlices * job.plan.spanY));
    this->RowHigh.resize(this->RowLow.size());
    this->Window.resize(static_cast<std::size_t>(this->SlicePixels * this->Lanes));
    this->Columns.resize(static_cast<std::size_t>(span * this->Lanes));
    this->WindowZeros.assign(static_cast<std::size_t>(span * this->Lanes), W(0));
    this->Histograms.resize(static_cast<std::size_t>(tile * this->Lanes));
    this->Upper.resize(tile);
    this->Below.resize(tile);
    this->At.resize(tile);
    this->Query.resize(tile);
    this->BoxCounts.resize(tile);
    this->CountX.resize(tile);
    const std::vector<double>& t = job.thresholds;
    for (int u = 0; u <= this->Bins; ++u)
    {
      this->LowerEnd.push_back(t[std::max(u - 1, 0)]);
      this->UpperEnd.push_back(t[std::min(u, this->Bins - 1)]);
    }
    // Row b: ones in lanes b and above (a voxel of bin b counts in each); row Bins (no bin)
    // is empty.
    this->Masks.assign(static_cast<std::size_t>((this->Bins + 1) * this->Lanes), W(0));
    for (int b = 0; b < this->Bins; ++b)
      for (int c = b; c < this->Lanes; ++c)
        this->Masks[b * this->Lanes + c] = W(1);
  }

  /// Output columns [x0, x0 + nx) x [y0, y0 + ny) (volume coordinates), slices [z0, z1).
  /// Outputs the tile's slices z0 .. z1 - 1, each one a unit of `progress`.
  void compute(std::int64_t x0, std::int64_t nx, std::int64_t y0, std::int64_t ny, std::int64_t z0,
    std::int64_t z1, ChunkProgress& progress)
  {
    const Index3& dims = this->Volume.dims;
    const Radius& r = this->Job.radius;
    this->X0 = x0;
    this->NX = nx;
    this->HX0 = std::max<std::int64_t>(0, x0 - r.x);
    this->HX1 = std::min<std::int64_t>(dims[0], x0 + nx + r.x);
    this->HY0 = std::max<std::int64_t>(0, y0 - r.y);
    this->HY1 = std::min<std::int64_t>(dims[1], y0 + ny + r.y);
    for (std::int64_t i = 0; i < nx; ++i)
      this->CountX[i] = static_cast<double>(clippedWindowCount(x0 + i, r.x, dims[0]));
    const std::int64_t pixels = (this->HX1 - this->HX0) * (this->HY1 - this->HY0);
    std::fill(this->Window.begin(), this->Window.begin() + pixels * this->Lanes, W(0));
    for (std::int64_t s = std::max<std::int64_t>(0, z0 - r.z);
         s <= std::min<std::int64_t>(dims[2] - 1, z0 + r.z); ++s)
    {
      this->moveSlice(s, -1);
    }
    for (std::int64_t z = z0; z < z1; ++z)
    {
      if (z > z0)
      {
        const std::int64_t entering = z + r.z, leaving = z - r.z - 1;
        this->moveSlice(entering < dims[2] ? entering : -1, leaving);
      }
      this->outputSlice(y0, ny, z);
      if (!progress.advance())
        return;
    }
  }

private:
  std::int64_t width() const { return this->HX1 - this->HX0; }

  /// Window row y (volume coordinates), or a row of zeros outside the volume.
  const W* windowRow(std::int64_t y) const
  {
    return y >= this->HY0 && y < this->HY1
      ? &this->Window[(y - this->HY0) * this->width() * this->Lanes]
      : this->WindowZeros.data();
  }

  /// The bins of row y of slice s (from HX0), in the ring: written when the slice enters,
  /// read while it is in the z window and when it leaves.
  B* binsOf(std::int64_t s, std::int64_t y)
  {
    return &this->SliceBins[(s % this->RingSlices) * this->SlicePixels +
      (y - this->HY0) * this->width()];
  }

  /// Adds the bins of slice `entering` to the window and removes those of `leaving` (-1:
  /// none), finding the entering voxels' bins on the way.
  void moveSlice(std::int64_t entering, std::int64_t leaving)
  {
    const std::int64_t width = this->width();
    const std::int64_t stride = this->Volume.stride;
    // A tile's rows are short and a row of the volume apart, which the processor's
    // prefetchers do not follow: each row of the next entering slice is asked for (into
    // the L1 cache) as this one moves, a slice's work before it is read.
    const std::int64_t next =
      entering >= 0 && entering + 1 < this->Volume.dims[2] ? entering + 1 : -1;
    const std::int64_t rowBytes = width * stride * std::int64_t(sizeof(T));
    for (std::int64_t y = this->HY0; y < this->HY1; ++y)
    {
      if (next >= 0)
      {
        const char* ahead =
          reinterpret_cast<const char*>(this->Volume.row(y, next) + this->HX0 * stride);
        for (std::int64_t b = 0; b < rowBytes; b += 64)
          __builtin_prefetch(ahead + b, 0, 3);
        __builtin_prefetch(ahead + rowBytes - 1, 0, 3);
      }
      B* in = nullptr;
      if (entering >= 0)
      {
        in = this->binsOf(entering, y);
        this->Bin.row(this->Volume.row(y, entering) + this->HX0 * stride, stride, width, in);
        const std::size_t at = this->rowRangeIndex(entering, y);
        runRows<BinRange<B>>(
          this->Job.simd, static_cast<const B*>(in), width, &this->RowLow[at], &this->RowHigh[at]);
      }
      const B* out = leaving >= 0 ? this->binsOf(leaving, y) : nullptr;
      // A row whose entering and leaving voxels share their bins leaves the window as it is.
      if (in && out && std::equal(out, out + width, static_cast<const B*>(in)))
        continue;
      runRows<MoveRow<W, Fixed, B>>(this->Job.simd, static_cast<const B*>(in), out, width,
        &this->Window[(y - this->HY0) * width * this->Lanes],
        static_cast<const W*>(this->Masks.data()), this->Lanes, this->Bins);
    }
  }

  /// The openness of output rows [y0, y0 + ny) of slice z from the window (the counts of
  /// the slices around z). Per output row: the query's bin; the columns (the sums of the
  /// window rows around the row) slid one row down from the row before, or summed anew;
  /// the x window's counts below and in the query's bin (RowQuery); the openness. A row
  /// whose boxes hold one bin only (uniformBin) needs no columns: its counts follow from
  /// the bin, and the next row's columns from the same constant.
  void outputSlice(std::int64_t y0, std::int64_t ny, std::int64_t z)
  {
    const Radius& r = this->Job.radius;
    const Index3& dims = this->Volume.dims;
    const std::int64_t values = this->width() * this->Lanes;
    // The row whose columns are held, and the last uniform row and its bin (y0 - 2: none).
    std::int64_t columnsRow = y0 - 2, uniformRow = y0 - 2;
    int uniform = -1;
    for (std::int64_t y = y0; y < y0 + ny; ++y)
    {
      this->queryBins(y, z);
      const int bin = this->uniformBin(y, z);
      if (bin >= 0)
      {
        this->uniformCounts(bin, y, z);
        uniform = bin;
        uniformRow = y;
      }
      else
      {
        if (uniformRow == y - 1 && columnsRow != y - 1)
        {
          this->constantColumns(uniform, y - 1, z);
          columnsRow = y - 1;
        }
        if (columnsRow == y - 1)
          runRows<SlideRows<L, W>>(this->Job.simd, this->Columns.data(),
            this->windowRow(y + r.y < dims[1] ? y + r.y : -1), this->windowRow(y - r.y - 1),
            values);
        else
        {
          std::fill(this->Columns.begin(), this->Columns.begin() + values, L(0));
          for (std::int64_t w = std::max<std::int64_t>(0, y - r.y);
               w <= std::min<std::int64_t>(dims[1] - 1, y + r.y); ++w)
            runRows<SlideRows<L, W>>(this->Job.simd, this->Columns.data(), this->windowRow(w),
              this->WindowZeros.data(), values);
        }
        columnsRow = y;
        runRowsOfWidth<RowQueryOf>(this->Job.simd, static_cast<const L*>(this->Columns.data()),
          this->width(), this->X0 - this->HX0, this->NX, std::int64_t(r.x), this->Lanes,
          static_cast<const int*>(this->Upper.data()), this->Bins, this->Histograms.data(),
          this->Below.data(), this->At.data());
      }
      this->writeOpenness(y, z);
    }
  }

  /// Where the ranges of the bins of row y of slice s are kept.
  std::size_t rowRangeIndex(std::int64_t s, std::int64_t y) const
  {
    return static_cast<std::size_t>(
      (s % this->RingSlices) * this->Job.plan.spanY + (y - this->HY0));
  }

  /// The bin of every voxel of the boxes of output row y of slice z (the rows and slices
  /// of its y and z windows, across the tile grown by the radius) where they share one,
  /// else -1.
  int uniformBin(std::int64_t y, std::int64_t z) const
  {
    const Radius& r = this->Job.radius;
    const Index3& dims = this->Volume.dims;
    int bin = -1;
    for (std::int64_t s = std::max<std::int64_t>(0, z - r.z);
         s <= std::min<std::int64_t>(dims[2] - 1, z + r.z); ++s)
      for (std::int64_t w = std::max<std::int64_t>(0, y - r.y);
           w <= std::min<std::int64_t>(dims[1] - 1, y + r.y); ++w)
      {
        const std::size_t at = this->rowRangeIndex(s, w);
        const int low = this->RowLow[at];
        if (low != this->RowHigh[at] || (bin >= 0 && low != bin))
          return -1;
        bin = low;
      }
    return bin;
  }

  /// Voxels in the y and z windows of row y of slice z (clipped to the volume).
  std::int64_t windowCountYZ(std::int64_t y, std::int64_t z) const
  {
    const Radius& r = this->Job.radius;
    const Index3& dims = this->Volume.dims;
    return clippedWindowCount(y, r.y, dims[1]) * clippedWindowCount(z, r.z, dims[2]);
  }

  /// RowQuery's counts for row y of slice z whose boxes hold bin b only: a box's n voxels
  /// are at or below every threshold from t_b, none below it.
  void uniformCounts(int b, std::int64_t y, std::int64_t z)
  {
    const std::int64_t countYZ = this->windowCountYZ(y, z);
    for (std::int64_t i = 0; i < this->NX; ++i)
    {
      const auto n =
        static_cast<std::uint32_t>(static_cast<std::int64_t>(this->CountX[i]) * countYZ);
      const int u = this->Upper[i];
      this->Below[i] = u - 1 >= b ? n : 0;
      this->At[i] = u == b && u < this->Bins ? n : 0;
    }
  }

  /// The columns of row y of slice z whose window rows hold bin b only: each pixel the
  /// voxel count of its y and z windows in the lanes of bin b's mask.
  void constantColumns(int b, std::int64_t y, std::int64_t z)
  {
    const L n = static_cast<L>(this->windowCountYZ(y, z));
    const W* mask = &this->Masks[std::size_t(b) * this->Lanes];
    for (std::int64_t x = 0; x < this->width(); ++x)
      for (int c = 0; c < this->Lanes; ++c)
        this->Columns[x * this->Lanes + c] = static_cast<L>(n * L(mask[c]));
  }

  /// The query of each output voxel of row y of slice z, and its bin.
  void queryBins(std::int64_t y, std::int64_t z)
  {
    const HistogramQuery& query = this->Job.query;
    if (!query.values && !query.isoValue) // the voxels' own values, and the bins kept
    {
      runRows<VoxelQueries<T, B>>(this->Job.simd,
        this->Volume.row(y, z) + this->X0 * this->Volume.stride, this->Volume.stride,
        static_cast<const B*>(this->binsOf(z, y) + (this->X0 - this->HX0)), this->NX,
        this->Query.data(), this->Upper.data());
      return;
    }
    const std::int64_t out = this->outputIndex(y, z);
    for (std::int64_t i = 0; i < this->NX; ++i)
    {
      this->Query[i] = query.values ? query.values[out + i] : *query.isoValue;
      this->Upper[i] = this->Bin.search(this->Query[i]);
    }
  }

  /// The openness of row y of slice z from the counts below and in each query's bin.
  void writeOpenness(std::int64_t y, std::int64_t z)
  {
    const std::vector<double>& t = this->Job.thresholds;
    const auto countYZ = static_cast<double>(this->windowCountYZ(y, z));
    for (std::int64_t i = 0; i < this->NX; ++i)
      this->BoxCounts[i] = this->CountX[i] * countYZ;
    runRows<CdfOpenness>(this->Job.simd, static_cast<const double*>(this->Query.data()),
      static_cast<const int*>(this->Upper.data()),
      static_cast<const double*>(this->BoxCounts.data()),
      static_cast<const std::uint32_t*>(this->Below.data()),
      static_cast<const std::uint32_t*>(this->At.data()),
      static_cast<const double*>(this->LowerEnd.data()),
      static_cast<const double*>(this->UpperEnd.data()), t.front(), t.back(), this->Bins, this->NX,
      this->Job.openness + this->outputIndex(y, z));
    if (this->Job.range)
      this->Job.range->add(this->Job.openness + this->outputIndex(y, z), this->NX);
  }

  /// Index in the output of voxel (X0, y, z).
  std::int64_t outputIndex(std::int64_t y, std::int64_t z) const
  {
    const Region& region = this->Job.region;
    return ((z - region.begin[2]) * region.size[1] + (y - region.begin[1])) * region.size[0] +
      (this->X0 - region.begin[0]);
  }

  const TypedVolume<T>& Volume;
  const HistogramJob& Job;
  const BinOf<T>& Bin;
  int Bins, Lanes;
  std::int64_t RingSlices = 0, SlicePixels = 0;
  std::int64_t X0 = 0, NX = 0, HX0 = 0, HX1 = 0, HY0 = 0, HY1 = 0;
  std::vector<W> Window;
  std::vector<L> Columns;         // one row of the y window's sums of the window
  std::vector<W> WindowZeros;     // a window row outside the volume
  std::vector<B> SliceBins;       // the ring of the slices' bins (binsOf)
  std::vector<B> RowLow, RowHigh; // per row of the ring's slices: its lowest and highest bin
  std::vector<W> Masks;           // row b: ones in the lanes from b (cumulative counts)
  std::vector<L> Histograms;      // RowQuery's box histograms of one output row
  std::vector<int> Upper;
  std::vector<std::uint32_t> Below, At;
  std::vector<double> Query;
  std::vector<double> BoxCounts, CountX;  // per output of the row: its box's voxels, its x window's
  std::vector<double> LowerEnd, UpperEnd; // per bin u: t_(u-1) and t_u (CdfOpenness)
};

template <class T, class L, class W, int Fixed>
bool computeTiles(const TypedVolume<T>& volume, const HistogramJob& job, const Execution& execution)
{
  const BinOf<T> bin(job.thresholds, job.simd);
  const Region& region = job.region;
  const TilePlan& plan = job.plan;
  const std::int64_t units = plan.units();
  const int threads = resolveThreadCount(execution.threads);
  // Progress by output slice: a small volume has as few units as threads.
  const std::int64_t slices = units / plan.zParts * region.size[2];
  return parallelFor(
    units, static_cast<int>(std::min<std::int64_t>(units, 1 << 20)), threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      TileHistograms<T, L, W, Fixed> state(volume, job, bin);
      for (std::int64_t u = begin; u < end && !progress.stopped(); ++u)
      {
        const std::int64_t part = u % plan.zParts, t = u / plan.zParts;
        const std::int64_t tx = t % plan.tilesX, ty = t / plan.tilesX;
        const std::int64_t x0 = region.begin[0] + tx * plan.sideX;
        const std::int64_t y0 = region.begin[1] + ty * plan.sideY;
        const std::int64_t z0 = region.begin[2] + region.size[2] * part / plan.zParts;
        const std::int64_t z1 = region.begin[2] + region.size[2] * (part + 1) / plan.zParts;
        state.compute(x0, std::min(plan.sideX, region.begin[0] + region.size[0] - x0), y0,
          std::min(plan.sideY, region.begin[1] + region.size[1] - y0), z0, z1, progress);
      }
    },
    slices);
}

} // namespace

bool computeHistogramOpenness(const VolumeView& view, const Region& region, const Radius& radius,
  const std::vector<double>& thresholds, const HistogramQuery& query, float* openness,
  OutputRange* range, const Execution& execution)
{
  ConcurrentRange seen;
  // The largest box: its count must fit the lanes.
  std::int64_t largest = 1;
  const int r[3] = { radius.x, radius.y, radius.z };
  for (int a = 0; a < 3; ++a)
    largest *= std::min<std::int64_t>(2 * std::int64_t(r[a]) + 1, view.dims[a]);
  const int laneBytes = largest <= 0xFFFF ? 2 : 4;
  const int lanes = laneCount(static_cast<int>(thresholds.size()));
  const bool done = dispatchScalarType(view.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const TypedVolume<T> volume(view);
      const std::int64_t inputBytes = view.voxelCount() * static_cast<std::int64_t>(sizeof(T));
      const HistogramJob job{ planTiles(region.size, view.dims, inputBytes, radius, lanes,
                                laneBytes, resolveThreadCount(execution.threads)),
        region, radius, thresholds, query, openness, cpuSimdTierUpTo(SimdTier::Avx512),
        range ? &seen : nullptr };
      // The default 64 bins in 16-bit lanes: loops of a known length.
      if (narrowWindow(radius) && laneBytes == 2 && lanes == 64)
        return computeTiles<T, std::uint16_t, std::uint8_t, 64>(volume, job, execution);
      if (narrowWindow(radius))
        return laneBytes == 2
          ? computeTiles<T, std::uint16_t, std::uint8_t, 0>(volume, job, execution)
          : computeTiles<T, std::uint32_t, std::uint8_t, 0>(volume, job, execution);
      return laneBytes == 2
        ? computeTiles<T, std::uint16_t, std::uint16_t, 0>(volume, job, execution)
        : computeTiles<T, std::uint32_t, std::uint32_t, 0>(volume, job, execution);
    });
  if (done && range)
    *range = seen.result();
  return done;
}

} // namespace detail
} // namespace vao
