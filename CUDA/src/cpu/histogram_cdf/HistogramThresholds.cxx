// The value summary and the threshold placement of Histogram CDF (vao/HistogramCdf.h).
#include "vao/HistogramCdf.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"

#include "vao/Validation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <type_traits>

namespace vao
{

ValueHistogram ValueHistogram::forRange(ScalarType type, double lowest, double highest)
{
  ValueHistogram h;
  h.lowest = lowest;
  h.highest = highest;
  // Integers spanning at most kMaximumCells values: one cell each, so that every distinct
  // value can become a threshold. (highest - lowest) is exact for such ranges.
  h.integerCells =
    scalarTypeIsIntegral(type) && highest - lowest < static_cast<double>(kMaximumCells);
  const std::int64_t cells = h.integerCells ? static_cast<std::int64_t>(highest - lowest) + 1
                                            : (highest > lowest ? kMaximumCells : 1);
  h.counts.assign(static_cast<std::size_t>(cells), 0);
  h.minimum.assign(static_cast<std::size_t>(cells), std::numeric_limits<double>::infinity());
  h.maximum.assign(static_cast<std::size_t>(cells), -std::numeric_limits<double>::infinity());
  return h;
}

namespace
{

/// The cells of a ValueHistogram as numbers: a value's position on them, clamped to them
/// before the conversion (so that a position beyond them, even an infinite one where the
/// range is near the smallest doubles, gives the end cell). Halves: the width of a range
/// near the largest doubles does not overflow.
class CellGrid
{
public:
  explicit CellGrid(const ValueHistogram& histogram)
    : Lowest(histogram.lowest)
    , HalfLowest(histogram.lowest / 2)
    , HalfWidth(histogram.highest / 2 - histogram.lowest / 2)
    , Cells(static_cast<double>(histogram.counts.size()))
    , Last(static_cast<double>(histogram.counts.size() - 1))
    , IntegerCells(histogram.integerCells)
  {
  }

  bool integerCells() const { return this->IntegerCells; }
  /// Whether the cells have a width (a range of one value has one cell: 0).
  bool scaled() const { return this->HalfWidth > 0.0; }

  /// The position of finite v, a cell per integer, clamped to the cells; its integer
  /// part is the cell. (A position, not yet a cell: a row's loop computes it for every
  /// value and converts only the finite ones, without a branch.)
  double integerPosition(double v) const { return this->clamped(v - this->Lowest); }
  /// The position of finite v on equal cells over the range (scaled()), clamped.
  double scaledPosition(double v) const
  {
    return this->clamped((v / 2 - this->HalfLowest) / this->HalfWidth * this->Cells);
  }
  std::int32_t cell(double v) const
  {
    return static_cast<std::int32_t>(this->IntegerCells ? this->integerPosition(v)
        : this->scaled()                                ? this->scaledPosition(v)
                                                        : 0.0);
  }

private:
  double clamped(double at) const { return std::min(std::max(at, 0.0), this->Last); }

  double Lowest, HalfLowest, HalfWidth, Cells, Last;
  bool IntegerCells;
};

} // namespace

std::int64_t ValueHistogram::cell(double v) const
{
  return CellGrid(*this).cell(v);
}

std::int64_t ValueHistogram::totalCount() const
{
  std::int64_t total = 0;
  for (const std::int64_t c : this->counts)
    total += c;
  return total;
}

void ValueHistogram::merge(const ValueHistogram& other)
{
  for (std::size_t i = 0; i < this->counts.size() && i < other.counts.size(); ++i)
  {
    this->counts[i] += other.counts[i];
    this->minimum[i] = std::min(this->minimum[i], other.minimum[i]);
    this->maximum[i] = std::max(this->maximum[i], other.maximum[i]);
  }
}

namespace
{

/// Counts of 8- and 16-bit values, a cell per value, in four 32-bit counters per cell
/// that consecutive voxels take in turn: a run of equal values (air in a CT) would
/// otherwise increment one counter, each increment waiting for the one before it.
class InterleavedCounts
{
public:
  explicit InterleavedCounts(std::size_t cells)
    : Counts(4 * cells, 0)
  {
  }

  /// Counts n values `stride` apart into the cells from value `lowest` (clamped to the
  /// cells), moving the counters into `total` before they could overflow.
  template <class T>
  void addRow(const T* row, std::int64_t n, std::int64_t stride, std::int64_t lowest,
    std::vector<std::int64_t>& total)
  {
    if (this->Pending + n > kFlushAfter)
      this->addTo(total);
    this->Pending += n;
    const auto last = static_cast<std::int64_t>(this->Counts.size() / 4) - 1;
    std::uint32_t* counts = this->Counts.data();
    const auto cell = [&](std::int64_t i) {
      return 4 * std::min(last, std::max<std::int64_t>(0, std::int64_t(row[i * stride]) - lowest));
    };
    std::int64_t i = 0;
    for (; i + 4 <= n; i += 4)
    {
      ++counts[cell(i)];
      ++counts[cell(i + 1) + 1];
      ++counts[cell(i + 2) + 2];
      ++counts[cell(i + 3) + 3];
    }
    for (; i < n; ++i)
      ++counts[cell(i)];
  }

  /// Adds the counters to `total` (a count per cell) and clears them.
  void addTo(std::vector<std::int64_t>& total)
  {
    for (std::size_t c = 0; 4 * c < this->Counts.size(); ++c)
    {
      total[c] += std::int64_t(this->Counts[4 * c]) + this->Counts[4 * c + 1] +
        this->Counts[4 * c + 2] + this->Counts[4 * c + 3];
    }
    std::fill(this->Counts.begin(), this->Counts.end(), 0u);
    this->Pending = 0;
  }

private:
  static constexpr std::int64_t kFlushAfter = std::int64_t(1) << 31;
  std::vector<std::uint32_t> Counts;
  std::int64_t Pending = 0; // values counted since the last addTo
};

/// Counts and extrema of values on a ValueHistogram's cells, a cell's three together (one
/// cache line per value where three arrays take three), the extrema in V (float for float
/// data, exact). A row's cells are found first, in a loop the compiler vectorises.
template <class V>
class CellTallies
{
public:
  explicit CellTallies(const ValueHistogram& histogram)
    : Grid(histogram)
    , Tallies(histogram.counts.size(),
        Tally{ std::numeric_limits<V>::infinity(), -std::numeric_limits<V>::infinity(), 0 })
  {
  }

  /// Adds n values `stride` apart; non-finite ones are skipped.
  template <class T>
  void addRow(const T* row, std::int64_t n, std::int64_t stride)
  {
    this->RowCells.resize(static_cast<std::size_t>(n));
    std::int32_t* cells = this->RowCells.data();
    // ValueHistogram::cell, one loop per kind of grid; -1 marks a value that is not finite.
    const CellGrid grid = this->Grid; // a copy: its numbers stay in registers
    const auto findCells = [&](auto position)
    {
      for (std::int64_t i = 0; i < n; ++i)
      {
        const double v = static_cast<double>(row[i * stride]);
        const double at = position(v);
        cells[i] = std::isfinite(v) ? static_cast<std::int32_t>(at) : -1;
      }
    };
    if (grid.integerCells())
      findCells([&](double v) { return grid.integerPosition(v); });
    else if (grid.scaled())
      findCells([&](double v) { return grid.scaledPosition(v); });
    else
      findCells([](double) { return 0.0; });
    for (std::int64_t i = 0; i < n; ++i)
    {
      if (cells[i] < 0)
        continue;
      const V v = static_cast<V>(row[i * stride]);
      Tally& t = this->Tallies[cells[i]];
      ++t.count;
      t.minimum = std::min(t.minimum, v);
      t.maximum = std::max(t.maximum, v);
    }
  }

  /// Adds the tallies to `histogram` (on the same cells).
  void addTo(ValueHistogram& histogram) const
  {
    for (std::size_t c = 0; c < this->Tallies.size(); ++c)
    {
      const Tally& t = this->Tallies[c];
      histogram.counts[c] += t.count;
      histogram.minimum[c] = std::min(histogram.minimum[c], static_cast<double>(t.minimum));
      histogram.maximum[c] = std::max(histogram.maximum[c], static_cast<double>(t.maximum));
    }
  }

private:
  struct Tally
  {
    V minimum, maximum;
    std::int64_t count;
  };

  CellGrid Grid;
  std::vector<Tally> Tallies;
  std::vector<std::int32_t> RowCells;
};

/// A cell per integer holds one value: its extrema, where it has a count.
void setIntegerCellExtrema(ValueHistogram& histogram)
{
  if (!histogram.integerCells)
    return;
  for (std::size_t c = 0; c < histogram.counts.size(); ++c)
    if (histogram.counts[c] > 0)
      histogram.minimum[c] = histogram.maximum[c] = histogram.lowest + static_cast<double>(c);
}

/// Slices [begin, end) of the region of 8- or 16-bit data into `histogram`, a cell per
/// value: counts only, the cells' extrema being their values.
template <class T>
void countCellPerValue(const detail::TypedVolume<T>& volume, const Region& region,
  std::int64_t begin, std::int64_t end, detail::ChunkProgress& progress, ValueHistogram& histogram,
  std::mutex& merging)
{
  std::vector<std::int64_t> counts(histogram.counts.size(), 0);
  InterleavedCounts cellCounts(counts.size());
  for (std::int64_t k = begin; k < end && !progress.stopped(); ++k)
  {
    for (std::int64_t j = 0; j < region.size[1]; ++j)
    {
      const T* row = volume.row(region.begin[1] + j, region.begin[2] + k);
      cellCounts.addRow(row + region.begin[0] * volume.stride, region.size[0], volume.stride,
        static_cast<std::int64_t>(histogram.lowest), counts);
    }
    progress.advance();
  }
  cellCounts.addTo(counts);
  const std::lock_guard<std::mutex> lock(merging);
  for (std::size_t c = 0; c < counts.size(); ++c)
    histogram.counts[c] += counts[c];
  setIntegerCellExtrema(histogram);
}

/// Slices [begin, end) of the region of any other type into `histogram`.
template <class T>
void tallyCells(const detail::TypedVolume<T>& volume, const Region& region, std::int64_t begin,
  std::int64_t end, detail::ChunkProgress& progress, ValueHistogram& histogram, std::mutex& merging)
{
  CellTallies<typename std::conditional<std::is_same<T, float>::value, float, double>::type>
    tallies(histogram);
  for (std::int64_t k = begin; k < end && !progress.stopped(); ++k)
  {
    for (std::int64_t j = 0; j < region.size[1]; ++j)
    {
      const T* row = volume.row(region.begin[1] + j, region.begin[2] + k);
      tallies.addRow(row + region.begin[0] * volume.stride, region.size[0], volume.stride);
    }
    progress.advance();
  }
  // Counts add and extrema combine in any order: the result does not depend on it.
  const std::lock_guard<std::mutex> lock(merging);
  tallies.addTo(histogram);
  setIntegerCellExtrema(histogram);
}

} // namespace

Status addToValueHistogram(const VolumeView& view, const Region& region, ValueHistogram& histogram,
  const Execution& execution)
{
  Status status = checkRegion(view, region);
  if (!status.ok)
  {
    return status;
  }
  return catchOutOfMemory("the value histogram of Histogram CDF",
    [&]
    {
      std::mutex merging;
      const bool finished = detail::dispatchScalarType(view.type,
        [&](auto tag)
        {
          using T = decltype(tag);
          const detail::TypedVolume<T> volume(view);
          const int threads = detail::resolveThreadCount(execution.threads);
          return detail::parallelFor(region.size[2], threads, threads, execution,
            [&](std::int64_t begin, std::int64_t end, detail::ChunkProgress& progress)
            {
              if constexpr (std::is_integral<T>::value && sizeof(T) <= 2)
                countCellPerValue(volume, region, begin, end, progress, histogram, merging);
              else
                tallyCells(volume, region, begin, end, progress, histogram, merging);
            });
        });
      return finished ? Status::success() : Status::cancelled();
    });
}

std::vector<double> histogramThresholds(const ValueHistogram& histogram, int bins)
{
  std::vector<std::size_t> cells; // the non-empty ones, ascending
  for (std::size_t c = 0; c < histogram.counts.size(); ++c)
  {
    if (histogram.counts[c] > 0)
      cells.push_back(c);
  }
  std::vector<double> thresholds;
  const std::size_t n = cells.size();
  if (n == 0 || bins < 1)
  {
    return thresholds;
  }
  if (n <= static_cast<std::size_t>(bins) || bins == 1)
  {
    for (const std::size_t c : cells)
      thresholds.push_back(histogram.maximum[c]);
    if (bins == 1)
      thresholds.erase(thresholds.begin(), thresholds.end() - 1);
    return thresholds;
  }
  // t_0: the lowest value, so that q below every value gives 0 and F_0 counts its tie.
  thresholds.push_back(histogram.maximum[cells[0]]);
  auto weight = [&](std::size_t i)
  { return std::pow(static_cast<double>(histogram.counts[cells[i]]), 0.7); };
  double remaining = 0.0;
  for (std::size_t i = 1; i < n; ++i)
    remaining += weight(i);
  std::size_t left = static_cast<std::size_t>(bins) - 1; // thresholds still to place
  double run = 0.0;
  for (std::size_t i = 1; i < n; ++i)
  {
    run += weight(i);
    const bool last = i + 1 == n;
    // End a run when it holds its share of what is left, or when every cell left must
    // have a threshold of its own; the last threshold is always the highest value.
    if (last ||
      (left > 1 && (run >= remaining / static_cast<double>(left) || n - 1 - i <= left - 1)))
    {
      thresholds.push_back(histogram.maximum[cells[i]]);
      remaining -= run;
      run = 0.0;
      --left;
    }
  }
  return thresholds;
}

Status volumeThresholds(
  const VolumeView& volume, int bins, std::vector<double>& thresholds, const Execution& execution)
{
  Status status = checkVolume(volume);
  if (!status.ok)
  {
    return status;
  }
  return catchOutOfMemory("the value histogram of Histogram CDF",
    [&]
    {
      const ValueScan scan = scanValues(volume);
      const Status finite = finiteStatus(scan);
      if (!finite.ok)
      {
        return finite;
      }
      ValueHistogram histogram = ValueHistogram::forRange(volume.type, scan.minimum, scan.maximum);
      const Status added = addToValueHistogram(volume, Region::whole(volume), histogram, execution);
      if (added.ok)
      {
        thresholds = histogramThresholds(histogram, bins);
      }
      return added;
    });
}

std::string checkHistogramBins(int bins)
{
  if (bins >= kMinimumHistogramBins && bins <= kMaximumHistogramBins)
  {
    return std::string();
  }
  return "NumberOfBins must lie in [" + std::to_string(kMinimumHistogramBins) + ", " +
    std::to_string(kMaximumHistogramBins) + "] (got " + std::to_string(bins) + ")";
}

} // namespace vao
