// Histogram CDF on the CPU: the box histogram of every voxel over the thresholds' bins.
//
// A voxel falls in bin b = thresholdIndex(v) (v <= t_b, above t_(b-1)). The box counts of
// all bins are separable box sums of one-hot indicator volumes, computed together as
// vectors of `lanes` small unsigned integers per pixel. The work goes tile by tile
// (TileSize x TileSize output columns, a z-range each), which keeps a tile's state in the
// L2 cache and the extra memory far below the input's size:
//  - Window: the counts of the 2 Rz + 1 slices around z, per pixel of the tile grown by
//    the radius. Moving to the next slice adds one voxel's bin and removes one: O(1).
//  - Rows: the window summed along x (a running vector per row), then a running vector per
//    column along y gives the 3-D box histogram of each output voxel.
// The query q then needs F just below and at the bin of q: a masked sum of the histogram's
// lanes. Counts never exceed the box's voxel count; lanes are 16 bits when that fits and
// the intermediate sums may wrap (unsigned arithmetic is modular, and the final counts are
// below 2^16), else 32 bits. The lane loops are compiled for AVX2 as well (CpuDispatch.h).
#include "HistogramChannels.h"

#include "CpuDispatch.h"
#include "Parallel.h"
#include "VolumeAccess.h"

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

constexpr std::int64_t kTileSize = 48;
constexpr int kLaneMultiple = 16;

/// dst = window sum along x of `src` (width pixels of `lanes`), for outputs starting at
/// pixel `first`, `count` of them, half-width r; `run` is scratch of `lanes`.
template <class L>
struct RowSums
{
  static VAO_ALWAYS_INLINE void run(const L* src, std::int64_t width, std::int64_t first, std::int64_t count,
    std::int64_t r, int lanes, L* run, L* dst)
  {
    for (int c = 0; c < lanes; ++c)
      run[c] = 0;
    const std::int64_t lo = std::max<std::int64_t>(0, first - r);
    const std::int64_t hi = std::min<std::int64_t>(width - 1, first + r);
    for (std::int64_t x = lo; x <= hi; ++x)
    {
      const L* s = src + x * lanes;
      for (int c = 0; c < lanes; ++c)
        run[c] = static_cast<L>(run[c] + s[c]);
    }
    for (std::int64_t i = 0; i < count; ++i)
    {
      L* d = dst + i * lanes;
      for (int c = 0; c < lanes; ++c)
        d[c] = run[c];
      const std::int64_t entering = first + i + r + 1;
      const std::int64_t leaving = first + i - r;
      if (entering < width)
      {
        const L* s = src + entering * lanes;
        for (int c = 0; c < lanes; ++c)
          run[c] = static_cast<L>(run[c] + s[c]);
      }
      if (leaving >= 0)
      {
        const L* s = src + leaving * lanes;
        for (int c = 0; c < lanes; ++c)
          run[c] = static_cast<L>(run[c] - s[c]);
      }
    }
  }
};

/// run += entering - leaving (either may be null), over count * lanes values.
template <class L>
struct SlideRun
{
  static VAO_ALWAYS_INLINE void run(L* run, const L* entering, const L* leaving, std::int64_t values)
  {
    if (entering)
      for (std::int64_t c = 0; c < values; ++c)
        run[c] = static_cast<L>(run[c] + entering[c]);
    if (leaving)
      for (std::int64_t c = 0; c < values; ++c)
        run[c] = static_cast<L>(run[c] - leaving[c]);
  }
};

/// below[i] = sum of the lanes of histogram i under upper[i].
template <class L>
struct MaskedPrefix
{
  static VAO_ALWAYS_INLINE void run(const L* histograms, const int* upper, std::int64_t count, int lanes,
    std::uint32_t* below)
  {
    for (std::int64_t i = 0; i < count; ++i)
    {
      const L* h = histograms + i * lanes;
      const int u = upper[i];
      std::uint32_t sum = 0;
      for (int c = 0; c < lanes; ++c)
        sum += c < u ? static_cast<std::uint32_t>(h[c]) : 0u;
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
        this->Table[i] = static_cast<std::uint16_t>(
          thresholdIndex(lowest + static_cast<double>(i), thresholds.data(), static_cast<int>(thresholds.size())));
      }
    }
  }

  int operator()(T v) const
  {
    if constexpr (kTable)
    {
      return this->Table[static_cast<std::size_t>(static_cast<std::int64_t>(v) - std::numeric_limits<T>::lowest())];
    }
    else
    {
      return thresholdIndex(static_cast<double>(v), this->Thresholds.data(), static_cast<int>(this->Thresholds.size()));
    }
  }

private:
  static constexpr bool kTable = std::is_integral<T>::value && sizeof(T) <= 2;
  const std::vector<double>& Thresholds;
  std::vector<std::uint16_t> Table;
};

struct HistogramJob
{
  const Region& region;
  const Radius& radius;
  const std::vector<double>& thresholds;
  const HistogramQuery& query;
  float* openness;
  bool avx2;
};

/// One tile's state, reused for the tiles of one worker.
template <class T, class L>
class TileHistograms
{
public:
  TileHistograms(const TypedVolume<T>& volume, const HistogramJob& job, const BinOf<T>& bin)
    : Volume(volume)
    , Job(job)
    , Bin(bin)
    , Bins(static_cast<int>(job.thresholds.size()))
    , Lanes((Bins + kLaneMultiple - 1) / kLaneMultiple * kLaneMultiple)
  {
    const std::int64_t span = kTileSize + 2 * std::max(job.radius.x, job.radius.y);
    this->Window.resize(static_cast<std::size_t>(span * span * this->Lanes));
    this->Rows.resize(static_cast<std::size_t>(span * kTileSize * this->Lanes));
    this->Run.resize(static_cast<std::size_t>(kTileSize * this->Lanes));
    this->Scratch.resize(static_cast<std::size_t>(this->Lanes));
    this->Upper.resize(kTileSize);
    this->Below.resize(kTileSize);
    this->Query.resize(kTileSize);
  }

  /// Output columns [x0, x0 + nx) x [y0, y0 + ny) (volume coordinates), slices [z0, z1).
  void compute(std::int64_t x0, std::int64_t nx, std::int64_t y0, std::int64_t ny, std::int64_t z0, std::int64_t z1)
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
    std::fill(this->Window.begin(), this->Window.begin() + pixels * this->Lanes, L(0));
    for (std::int64_t s = std::max<std::int64_t>(0, z0 - r.z); s <= std::min<std::int64_t>(dims[2] - 1, z0 + r.z); ++s)
    {
      this->addSlice(s, 1);
    }
    for (std::int64_t z = z0; z < z1; ++z)
    {
      if (z > z0)
      {
        if (z + r.z < dims[2])
          this->addSlice(z + r.z, 1);
        if (z - r.z - 1 >= 0)
          this->addSlice(z - r.z - 1, -1);
      }
      this->outputSlice(y0, ny, z);
    }
  }

private:
  void addSlice(std::int64_t s, int sign)
  {
    const std::int64_t width = this->HX1 - this->HX0;
    const L step = static_cast<L>(sign);
    for (std::int64_t y = this->HY0; y < this->HY1; ++y)
    {
      const T* row = this->Volume.row(y, s);
      L* w = &this->Window[(y - this->HY0) * width * this->Lanes];
      for (std::int64_t x = this->HX0; x < this->HX1; ++x)
      {
        const int b = this->Bin(row[x * this->Volume.stride]);
        if (b < this->Bins)
        {
          L& lane = w[(x - this->HX0) * this->Lanes + b];
          lane = static_cast<L>(lane + step);
        }
      }
    }
  }

  void outputSlice(std::int64_t y0, std::int64_t ny, std::int64_t z)
  {
    const Radius& r = this->Job.radius;
    const Index3& dims = this->Volume.dims;
    const Region& region = this->Job.region;
    const std::int64_t width = this->HX1 - this->HX0;
    const std::int64_t nx = this->NX;
    const std::int64_t rowValues = nx * this->Lanes;
    for (std::int64_t y = this->HY0; y < this->HY1; ++y)
    {
      runRows<RowSums<L>>(this->Job.avx2, &this->Window[(y - this->HY0) * width * this->Lanes], width,
        this->X0 - this->HX0, nx, std::int64_t(r.x), this->Lanes, this->Scratch.data(),
        &this->Rows[(y - this->HY0) * rowValues]);
    }
    std::fill(this->Run.begin(), this->Run.end(), L(0));
    for (std::int64_t y = std::max<std::int64_t>(0, y0 - r.y); y <= std::min<std::int64_t>(dims[1] - 1, y0 + r.y); ++y)
    {
      runRows<SlideRun<L>>(this->Job.avx2, this->Run.data(), &this->Rows[(y - this->HY0) * rowValues],
        static_cast<const L*>(nullptr), rowValues);
    }
    const double* t = this->Job.thresholds.data();
    const HistogramQuery& query = this->Job.query;
    const double countZ = static_cast<double>(clippedWindowCount(z, r.z, dims[2]));
    for (std::int64_t y = y0; y < y0 + ny; ++y)
    {
      const T* row = this->Volume.row(y, z);
      const std::int64_t out =
        ((z - region.begin[2]) * region.size[1] + (y - region.begin[1])) * region.size[0] + (this->X0 - region.begin[0]);
      for (std::int64_t i = 0; i < nx; ++i)
      {
        const T v = row[(this->X0 + i) * this->Volume.stride];
        double q = static_cast<double>(v);
        if (query.values)
          q = query.values[out + i];
        else if (query.isoValue)
          q = *query.isoValue;
        this->Query[i] = q;
        this->Upper[i] = query.values || query.isoValue ? thresholdIndex(q, t, this->Bins) : this->Bin(v);
      }
      runRows<MaskedPrefix<L>>(this->Job.avx2, static_cast<const L*>(this->Run.data()),
        static_cast<const int*>(this->Upper.data()), nx, this->Lanes, this->Below.data());
      const double countYZ = static_cast<double>(clippedWindowCount(y, r.y, dims[1])) * countZ;
      for (std::int64_t i = 0; i < nx; ++i)
      {
        const int u = this->Upper[i];
        const double at = u < this->Bins ? static_cast<double>(this->Run[i * this->Lanes + u]) : 0.0;
        const double count = static_cast<double>(clippedWindowCount(this->X0 + i, r.x, dims[0])) * countYZ;
        this->Job.openness[out + i] = static_cast<float>(
          opennessHistogramCdfAt(this->Query[i], t, this->Bins, u, count, this->Below[i], at));
      }
      if (y + 1 < y0 + ny)
      {
        const std::int64_t entering = y + r.y + 1, leaving = y - r.y;
        runRows<SlideRun<L>>(this->Job.avx2, this->Run.data(),
          entering < dims[1] ? static_cast<const L*>(&this->Rows[(entering - this->HY0) * rowValues]) : nullptr,
          leaving >= 0 ? static_cast<const L*>(&this->Rows[(leaving - this->HY0) * rowValues]) : nullptr, rowValues);
      }
    }
  }

  const TypedVolume<T>& Volume;
  const HistogramJob& Job;
  const BinOf<T>& Bin;
  int Bins, Lanes;
  std::int64_t X0 = 0, NX = 0, HX0 = 0, HX1 = 0, HY0 = 0, HY1 = 0;
  std::vector<L> Window, Rows, Run, Scratch;
  std::vector<int> Upper;
  std::vector<std::uint32_t> Below;
  std::vector<double> Query;
};

template <class T, class L>
bool computeTiles(const TypedVolume<T>& volume, const HistogramJob& job, const Execution& execution)
{
  const BinOf<T> bin(job.thresholds);
  const Region& region = job.region;
  const std::int64_t tilesX = (region.size[0] + kTileSize - 1) / kTileSize;
  const std::int64_t tilesY = (region.size[1] + kTileSize - 1) / kTileSize;
  const int threads = resolveThreadCount(execution.threads);
  // Enough units for every thread several times over; each z-range starts its window anew.
  const std::int64_t zParts = std::min<std::int64_t>(
    region.size[2], std::max<std::int64_t>(1, (4 * threads + tilesX * tilesY - 1) / (tilesX * tilesY)));
  const std::int64_t units = tilesX * tilesY * zParts;
  return parallelFor(units, static_cast<int>(std::min<std::int64_t>(units, 1 << 20)), threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      TileHistograms<T, L> tile(volume, job, bin);
      for (std::int64_t u = begin; u < end && !progress.stopped(); ++u)
      {
        const std::int64_t part = u % zParts, t = u / zParts;
        const std::int64_t tx = t % tilesX, ty = t / tilesX;
        const std::int64_t x0 = region.begin[0] + tx * kTileSize, y0 = region.begin[1] + ty * kTileSize;
        const std::int64_t z0 = region.begin[2] + region.size[2] * part / zParts;
        const std::int64_t z1 = region.begin[2] + region.size[2] * (part + 1) / zParts;
        tile.compute(x0, std::min(kTileSize, region.begin[0] + region.size[0] - x0), y0,
          std::min(kTileSize, region.begin[1] + region.size[1] - y0), z0, z1);
        progress.advance();
      }
    });
}

} // namespace

bool computeHistogramOpenness(const VolumeView& view, const Region& region, const Radius& radius,
  const std::vector<double>& thresholds, const HistogramQuery& query, float* openness, const Execution& execution)
{
  const HistogramJob job{ region, radius, thresholds, query, openness, cpuHasAvx2() };
  // The largest box: its count must fit the lanes.
  std::int64_t largest = 1;
  const int r[3] = { radius.x, radius.y, radius.z };
  for (int a = 0; a < 3; ++a)
    largest *= std::min<std::int64_t>(2 * std::int64_t(r[a]) + 1, view.dims[a]);
  return dispatchScalarType(view.type, [&](auto tag) {
    using T = decltype(tag);
    const TypedVolume<T> volume(view);
    return largest <= 0xFFFF ? computeTiles<T, std::uint16_t>(volume, job, execution)
                             : computeTiles<T, std::uint32_t>(volume, job, execution);
  });
}

} // namespace detail
} // namespace vao
