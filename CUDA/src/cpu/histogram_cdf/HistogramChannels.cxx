// Histogram CDF on the CPU: the box histogram of every voxel over the thresholds' bins.
//
// A voxel falls in bin b = thresholdIndex(v) (v <= t_b, above t_(b-1)). The box counts of
// all bins are separable box sums of one-hot indicator volumes, computed together as
// vectors of `lanes` small unsigned integers per pixel. The work goes tile by tile
// (TileSize x TileSize output columns, a z-range each), which keeps a tile's state in the
// L2 cache and the extra memory far below the input's size:
//  - Window: the counts of the 2 Rz + 1 slices around z, per pixel of the tile grown by
//    the radius, in 8-bit lanes where 2 Rz + 1 fits. Moving to the next slice adds one
//    voxel's bin and removes one: O(1), and nothing where both fall in the same bin. Each
//    voxel's bin is found once per tile, when its slice enters, and kept in a ring of the
//    2 Rz + 2 slices' bins for the slice leaving and for the query.
//  - Rows: the window summed along x (a running vector per row), kept in a ring of the
//    2 Ry + 2 rows a y window and its next entering row span; a running vector per column
//    along y then gives the 3-D box histogram of each output voxel.
// The query q then needs F just below and at the bin of q: a masked sum of the histogram's
// lanes. Counts never exceed the box's voxel count; lanes are 16 bits when that fits and
// the intermediate sums may wrap (unsigned arithmetic is modular, and the final counts are
// below 2^16), else 32 bits. The lane loops are compiled for AVX2 as well (CpuDispatch.h).
#include "cpu/histogram_cdf/HistogramChannels.h"

#include "VolumeAccess.h"
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

constexpr int kLaneMultiple = 16;

/// Lanes of a bin count: a multiple of kLaneMultiple (the AVX2 width of 16-bit lanes).
int laneCount(int bins)
{
  return (bins + kLaneMultiple - 1) / kLaneMultiple * kLaneMultiple;
}

/// Whether the window's counts (at most 2 Rz + 1 per pixel) fit 8-bit lanes.
bool narrowWindow(const Radius& r)
{
  return 2 * std::int64_t(r.z) + 1 <= 0xFF;
}

/// Rows of x sums a tile keeps: those of a y window and its next entering row.
std::int64_t ringRows(const Radius& r)
{
  return 2 * std::int64_t(r.y) + 2;
}

/// Slices whose bins a tile keeps: those of a z window and its next entering slice.
std::int64_t ringSlices(const Radius& r)
{
  return 2 * std::int64_t(r.z) + 2;
}

/// Bytes of one worker's state for tiles of `tile` columns: the window counts of the tile
/// grown by the radius, and the ring of rows summed along x.
std::int64_t tileStateBytes(std::int64_t tile, const Radius& r, int lanes, int laneBytes)
{
  const std::int64_t span = tile + 2 * std::max(r.x, r.y);
  const int windowBytes = narrowWindow(r) ? 1 : laneBytes;
  return (span * span * windowBytes + std::min(ringRows(r), span) * tile * laneBytes) * lanes +
    ringSlices(r) * span * span * std::int64_t(sizeof(std::uint16_t));
}

/// The tile's side: 64 (larger tiles leave the L2 cache, smaller ones recount more of
/// their border), smaller when the workers' states would exceed an eighth of the input
/// (the rest of the 25% the filter may add goes to buffers that do not shrink with the
/// tile), down to 16.
std::int64_t tileSize(
  std::int64_t inputBytes, const Radius& r, int lanes, int laneBytes, int threads)
{
  std::int64_t tile = 64;
  while (tile > 16 && threads * tileStateBytes(tile, r, lanes, laneBytes) > inputBytes / 8)
  {
    tile -= 8;
  }
  return tile;
}

/// dst = window sum along x of `src` (width pixels of `lanes`), for outputs starting at
/// pixel `first`, `count` of them, half-width r. Each output is the previous one plus the
/// pixel entering the window minus the one leaving it (`zeros` stands for a pixel outside
/// the row): three loads and one store per vector of lanes.
template <class L, class W>
struct RowSums
{
  static VAO_ALWAYS_INLINE void run(const W* __restrict src, std::int64_t width, std::int64_t first,
    std::int64_t count, std::int64_t r, int lanes, const W* __restrict zeros, L* __restrict dst)
  {
    for (int c = 0; c < lanes; ++c)
      dst[c] = 0;
    const std::int64_t lo = std::max<std::int64_t>(0, first - r);
    const std::int64_t hi = std::min<std::int64_t>(width - 1, first + r);
    for (std::int64_t x = lo; x <= hi; ++x)
    {
      const W* __restrict s = src + x * lanes;
      for (int c = 0; c < lanes; ++c)
        dst[c] = static_cast<L>(dst[c] + L(s[c]));
    }
    for (std::int64_t i = 1; i < count; ++i)
    {
      const std::int64_t entering = first + i + r, leaving = first + i - r - 1;
      const W* __restrict in = entering < width ? src + entering * lanes : zeros;
      const W* __restrict out = leaving >= 0 ? src + leaving * lanes : zeros;
      const L* __restrict previous = dst + (i - 1) * lanes;
      L* __restrict d = dst + i * lanes;
      for (int c = 0; c < lanes; ++c)
        d[c] = static_cast<L>(previous[c] + L(in[c]) - L(out[c]));
    }
  }
};

/// run += entering - leaving over `values` lanes (`zeros` for a row outside the volume).
template <class L>
struct SlideRun
{
  static VAO_ALWAYS_INLINE void run(L* __restrict run, const L* __restrict entering,
    const L* __restrict leaving, std::int64_t values)
  {
    for (std::int64_t c = 0; c < values; ++c)
      run[c] = static_cast<L>(run[c] + entering[c] - leaving[c]);
  }
};

/// below[i] = sum of the lanes of histogram i under upper[i]: the lanes ANDed with row
/// upper[i] of `masks` (all ones below it) and added in the lanes' own width, which holds
/// any sum of a box's counts.
template <class L>
struct MaskedPrefix
{
  static VAO_ALWAYS_INLINE void run(const L* histograms, const int* upper, std::int64_t count,
    int lanes, const L* masks, std::uint32_t* below)
  {
    for (std::int64_t i = 0; i < count; ++i)
    {
      const L* h = histograms + i * lanes;
      const L* m = masks + static_cast<std::int64_t>(upper[i]) * lanes;
      L sum = 0;
      for (int c = 0; c < lanes; ++c)
        sum = static_cast<L>(sum + (h[c] & m[c]));
      below[i] = sum;
    }
  }
};

/// Bin of a value: a table over the whole type for 8- and 16-bit integers, else a search.
template <class T>
class BinOf
{
public:
  BinOf(const std::vector<double>& thresholds)
    : Thresholds(thresholds)
  {
    if (kTable)
    {
      const double lowest = static_cast<double>(std::numeric_limits<T>::lowest());
      this->Table.resize(std::size_t(1) << (8 * sizeof(T)));
      for (std::size_t i = 0; i < this->Table.size(); ++i)
      {
        this->Table[i] = static_cast<std::uint16_t>(thresholdIndex(
          lowest + static_cast<double>(i), thresholds.data(), static_cast<int>(thresholds.size())));
      }
    }
  }

  /// The bins of n values `stride` apart.
  void row(const T* in, std::int64_t stride, std::int64_t n, std::uint16_t* out) const
  {
    if constexpr (kTable)
    {
      const std::uint16_t* table =
        this->Table.data() - std::int64_t(std::numeric_limits<T>::lowest());
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = table[in[i * stride]];
    }
    else
    {
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = static_cast<std::uint16_t>((*this)(in[i * stride]));
    }
  }

  int operator()(T v) const
  {
    if constexpr (kTable)
    {
      return this->Table[static_cast<std::size_t>(
        static_cast<std::int64_t>(v) - std::numeric_limits<T>::lowest())];
    }
    else
    {
      return thresholdIndex(
        static_cast<double>(v), this->Thresholds.data(), static_cast<int>(this->Thresholds.size()));
    }
  }

private:
  static constexpr bool kTable = std::is_integral<T>::value && sizeof(T) <= 2;
  const std::vector<double>& Thresholds;
  std::vector<std::uint16_t> Table;
};

struct HistogramJob
{
  std::int64_t tile; // side of the tiles in columns
  const Region& region;
  const Radius& radius;
  const std::vector<double>& thresholds;
  const HistogramQuery& query;
  float* openness;
  SimdTier simd;
};

/// One tile's state, reused for the tiles of one worker: counts in lanes of L, the window's
/// in W (8-bit where they fit).
template <class T, class L, class W>
class TileHistograms
{
public:
  TileHistograms(const TypedVolume<T>& volume, const HistogramJob& job, const BinOf<T>& bin)
    : Volume(volume)
    , Job(job)
    , Bin(bin)
    , Bins(static_cast<int>(job.thresholds.size()))
    , Lanes(laneCount(Bins))
  {
    const std::int64_t tile = job.tile;
    const std::int64_t span = tile + 2 * std::max(job.radius.x, job.radius.y);
    this->RingRows = std::min(ringRows(job.radius), span);
    this->RingSlices = ringSlices(job.radius);
    this->SlicePixels = span * span;
    this->SliceBins.resize(static_cast<std::size_t>(this->RingSlices * this->SlicePixels));
    this->Window.resize(static_cast<std::size_t>(span * span * this->Lanes));
    this->Rows.resize(static_cast<std::size_t>(this->RingRows * tile * this->Lanes));
    this->Run.resize(static_cast<std::size_t>(tile * this->Lanes));
    this->Zeros.assign(static_cast<std::size_t>(tile * this->Lanes), L(0));
    this->WindowZeros.assign(static_cast<std::size_t>(this->Lanes), W(0));
    this->Upper.resize(tile);
    this->Below.resize(tile);
    this->Query.resize(tile);
    this->Masks.assign(static_cast<std::size_t>((this->Lanes + 1) * this->Lanes), L(0));
    for (int u = 0; u <= this->Lanes; ++u)
      for (int c = 0; c < u; ++c)
        this->Masks[u * this->Lanes + c] = static_cast<L>(~L(0));
  }

  /// Output columns [x0, x0 + nx) x [y0, y0 + ny) (volume coordinates), slices [z0, z1).
  void compute(std::int64_t x0, std::int64_t nx, std::int64_t y0, std::int64_t ny, std::int64_t z0,
    std::int64_t z1)
  {
    const Index3& dims = this->Volume.dims;
    const Radius& r = this->Job.radius;
    this->X0 = x0;
    this->NX = nx;
    this->HX0 = std::max<std::int64_t>(0, x0 - r.x);
    this->HX1 = std::min<std::int64_t>(dims[0], x0 + nx + r.x);
    this->HY0 = std::max<std::int64_t>(0, y0 - r.y);
    this->HY1 = std::min<std::int64_t>(dims[1], y0 + ny + r.y);
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
    }
  }

private:
  const L* zeros() const { return this->Zeros.data(); }

  /// Row y's x sums (outputs X0 ... X0 + NX - 1 of window row y), in the ring.
  L* rowSums(std::int64_t y)
  {
    return &this->Rows[((y - this->HY0) % this->RingRows) * this->NX * this->Lanes];
  }

  /// Sums window row y along x into its ring slot.
  const L* sumRow(std::int64_t y)
  {
    const std::int64_t width = this->HX1 - this->HX0;
    L* dst = this->rowSums(y);
    runRows<RowSums<L, W>>(this->Job.simd,
      static_cast<const W*>(&this->Window[(y - this->HY0) * width * this->Lanes]), width,
      this->X0 - this->HX0, this->NX, std::int64_t(this->Job.radius.x), this->Lanes,
      static_cast<const W*>(this->WindowZeros.data()), dst);
    return dst;
  }

  /// Adds the bins of slice `entering` to the window and removes those of `leaving` (-1:
  /// none), in one pass that leaves a pixel alone when both voxels fall in the same bin
  /// (most of a smooth volume).
  void moveSlice(std::int64_t entering, std::int64_t leaving)
  {
    const std::int64_t width = this->HX1 - this->HX0;
    const std::int64_t stride = this->Volume.stride;
    const int bins = this->Bins;
    for (std::int64_t y = this->HY0; y < this->HY1; ++y)
    {
      std::uint16_t* in = nullptr;
      if (entering >= 0)
      {
        in = this->binsOf(entering, y);
        this->Bin.row(this->Volume.row(y, entering) + this->HX0 * stride, stride, width, in);
      }
      const std::uint16_t* out = leaving >= 0 ? this->binsOf(leaving, y) : nullptr;
      W* w = &this->Window[(y - this->HY0) * width * this->Lanes];
      for (std::int64_t x = 0; x < width; ++x)
      {
        // A missing slice's voxel is in no bin (index Bins), as a value above every threshold.
        const int added = in ? in[x] : bins;
        const int removed = out ? out[x] : bins;
        if (added == removed)
          continue;
        W* pixel = w + x * this->Lanes;
        if (added < bins)
          pixel[added] = static_cast<W>(pixel[added] + 1);
        if (removed < bins)
          pixel[removed] = static_cast<W>(pixel[removed] - 1);
      }
    }
  }

  /// The bins of row y of slice s (from HX0), in the ring: written when the slice enters,
  /// read while it is in the z window and when it leaves.
  std::uint16_t* binsOf(std::int64_t s, std::int64_t y)
  {
    return &this->SliceBins[(s % this->RingSlices) * this->SlicePixels +
      (y - this->HY0) * (this->HX1 - this->HX0)];
  }

  /// The openness of output rows [y0, y0 + ny) of slice z from the window (the counts of
  /// the slices around z): the run along y started on the window rows around y0 summed
  /// along x (RowSums), then per output row the query's bin, the masked prefix of the run
  /// (the count below that bin) and the openness, before the run slides one row down by
  /// the next entering row's x sums. The run holds one row of histograms, not a plane.
  void outputSlice(std::int64_t y0, std::int64_t ny, std::int64_t z)
  {
    const Radius& r = this->Job.radius;
    const Index3& dims = this->Volume.dims;
    const Region& region = this->Job.region;
    const std::int64_t nx = this->NX;
    const std::int64_t rowValues = nx * this->Lanes;
    std::fill(this->Run.begin(), this->Run.end(), L(0));
    for (std::int64_t y = std::max<std::int64_t>(0, y0 - r.y);
         y <= std::min<std::int64_t>(dims[1] - 1, y0 + r.y); ++y)
    {
      runRows<SlideRun<L>>(
        this->Job.simd, this->Run.data(), this->sumRow(y), this->zeros(), rowValues);
    }
    const double* t = this->Job.thresholds.data();
    const HistogramQuery& query = this->Job.query;
    const double countZ = static_cast<double>(clippedWindowCount(z, r.z, dims[2]));
    for (std::int64_t y = y0; y < y0 + ny; ++y)
    {
      const T* row = this->Volume.row(y, z);
      const std::uint16_t* bins = this->binsOf(z, y);
      const std::int64_t out =
        ((z - region.begin[2]) * region.size[1] + (y - region.begin[1])) * region.size[0] +
        (this->X0 - region.begin[0]);
      for (std::int64_t i = 0; i < nx; ++i)
      {
        const T v = row[(this->X0 + i) * this->Volume.stride];
        double q = static_cast<double>(v);
        if (query.values)
          q = query.values[out + i];
        else if (query.isoValue)
          q = *query.isoValue;
        this->Query[i] = q;
        this->Upper[i] = query.values || query.isoValue ? thresholdIndex(q, t, this->Bins)
                                                        : bins[this->X0 + i - this->HX0];
      }
      runRows<MaskedPrefix<L>>(this->Job.simd, static_cast<const L*>(this->Run.data()),
        static_cast<const int*>(this->Upper.data()), nx, this->Lanes,
        static_cast<const L*>(this->Masks.data()), this->Below.data());
      const double countYZ = static_cast<double>(clippedWindowCount(y, r.y, dims[1])) * countZ;
      for (std::int64_t i = 0; i < nx; ++i)
      {
        const int u = this->Upper[i];
        const double at =
          u < this->Bins ? static_cast<double>(this->Run[i * this->Lanes + u]) : 0.0;
        const double count =
          static_cast<double>(clippedWindowCount(this->X0 + i, r.x, dims[0])) * countYZ;
        this->Job.openness[out + i] = static_cast<float>(
          opennessHistogramCdfAt(this->Query[i], t, this->Bins, u, count, this->Below[i], at));
      }
      if (y + 1 < y0 + ny)
      {
        const std::int64_t entering = y + r.y + 1, leaving = y - r.y;
        // The leaving row is still in the ring: it holds 2 Ry + 2 rows.
        const L* in = entering < dims[1] ? this->sumRow(entering) : this->zeros();
        const L* out = leaving >= 0 ? static_cast<const L*>(this->rowSums(leaving)) : this->zeros();
        runRows<SlideRun<L>>(this->Job.simd, this->Run.data(), in, out, rowValues);
      }
    }
  }

  const TypedVolume<T>& Volume;
  const HistogramJob& Job;
  const BinOf<T>& Bin;
  int Bins, Lanes;
  std::int64_t RingRows = 0, RingSlices = 0, SlicePixels = 0;
  std::int64_t X0 = 0, NX = 0, HX0 = 0, HX1 = 0, HY0 = 0, HY1 = 0;
  std::vector<W> Window;
  std::vector<L> Rows, Run;
  std::vector<L> Zeros;                 // a row of pixels outside the volume
  std::vector<W> WindowZeros;           // one window pixel outside the volume
  std::vector<std::uint16_t> SliceBins; // the ring of the slices' bins (binsOf)
  std::vector<L> Masks;                 // row u: all ones in the lanes below u
  std::vector<int> Upper;
  std::vector<std::uint32_t> Below;
  std::vector<double> Query;
};

template <class T, class L, class W>
bool computeTiles(const TypedVolume<T>& volume, const HistogramJob& job, const Execution& execution)
{
  const BinOf<T> bin(job.thresholds);
  const Region& region = job.region;
  const std::int64_t tile = job.tile;
  const std::int64_t tilesX = (region.size[0] + tile - 1) / tile;
  const std::int64_t tilesY = (region.size[1] + tile - 1) / tile;
  const int threads = resolveThreadCount(execution.threads);
  // Enough units for every thread several times over; each z-range starts its window anew.
  const std::int64_t zParts = std::min<std::int64_t>(region.size[2],
    std::max<std::int64_t>(1, (4 * threads + tilesX * tilesY - 1) / (tilesX * tilesY)));
  const std::int64_t units = tilesX * tilesY * zParts;
  return parallelFor(units, static_cast<int>(std::min<std::int64_t>(units, 1 << 20)), threads,
    execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      TileHistograms<T, L, W> state(volume, job, bin);
      for (std::int64_t u = begin; u < end && !progress.stopped(); ++u)
      {
        const std::int64_t part = u % zParts, t = u / zParts;
        const std::int64_t tx = t % tilesX, ty = t / tilesX;
        const std::int64_t x0 = region.begin[0] + tx * tile, y0 = region.begin[1] + ty * tile;
        const std::int64_t z0 = region.begin[2] + region.size[2] * part / zParts;
        const std::int64_t z1 = region.begin[2] + region.size[2] * (part + 1) / zParts;
        state.compute(x0, std::min(tile, region.begin[0] + region.size[0] - x0), y0,
          std::min(tile, region.begin[1] + region.size[1] - y0), z0, z1);
        progress.advance();
      }
    });
}

} // namespace

bool computeHistogramOpenness(const VolumeView& view, const Region& region, const Radius& radius,
  const std::vector<double>& thresholds, const HistogramQuery& query, float* openness,
  const Execution& execution)
{
  // The largest box: its count must fit the lanes.
  std::int64_t largest = 1;
  const int r[3] = { radius.x, radius.y, radius.z };
  for (int a = 0; a < 3; ++a)
    largest *= std::min<std::int64_t>(2 * std::int64_t(r[a]) + 1, view.dims[a]);
  const int laneBytes = largest <= 0xFFFF ? 2 : 4;
  const int lanes = laneCount(static_cast<int>(thresholds.size()));
  return dispatchScalarType(view.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const TypedVolume<T> volume(view);
      const std::int64_t inputBytes = view.voxelCount() * static_cast<std::int64_t>(sizeof(T));
      const HistogramJob job{
        tileSize(inputBytes, radius, lanes, laneBytes, resolveThreadCount(execution.threads)),
        region, radius, thresholds, query, openness, cpuSimdTierUpTo(SimdTier::Avx2)
      }; // AVX-512 loses here
      if (narrowWindow(radius))
        return laneBytes == 2
          ? computeTiles<T, std::uint16_t, std::uint8_t>(volume, job, execution)
          : computeTiles<T, std::uint32_t, std::uint8_t>(volume, job, execution);
      return laneBytes == 2 ? computeTiles<T, std::uint16_t, std::uint16_t>(volume, job, execution)
                            : computeTiles<T, std::uint32_t, std::uint32_t>(volume, job, execution);
    });
}

} // namespace detail
} // namespace vao
