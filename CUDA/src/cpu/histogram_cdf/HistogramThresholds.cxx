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

std::int64_t ValueHistogram::cell(double v) const
{
  const auto last = static_cast<std::int64_t>(this->counts.size()) - 1;
  if (this->integerCells)
  {
    return std::min<std::int64_t>(
      last, std::max<std::int64_t>(0, static_cast<std::int64_t>(v - this->lowest)));
  }
  // Halves: the width of a range near the largest doubles does not overflow.
  const double width = this->highest / 2 - this->lowest / 2;
  if (!(width > 0.0))
  {
    return 0;
  }
  const double at = (v / 2 - this->lowest / 2) / width * static_cast<double>(this->counts.size());
  return std::min<std::int64_t>(last, std::max<std::int64_t>(0, static_cast<std::int64_t>(at)));
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
              ValueHistogram part = histogram;
              std::fill(part.counts.begin(), part.counts.end(), 0);
              constexpr bool kCellPerValue = std::is_integral<T>::value && sizeof(T) <= 2;
              InterleavedCounts cellCounts(kCellPerValue ? part.counts.size() : 0);
              for (std::int64_t k = begin; k < end && !progress.stopped(); ++k)
              {
                for (std::int64_t j = 0; j < region.size[1]; ++j)
                {
                  const T* row = volume.row(region.begin[1] + j, region.begin[2] + k);
                  if constexpr (kCellPerValue)
                  {
                    // A cell per value: count only; the cells' extrema are their values.
                    cellCounts.addRow(row + region.begin[0] * volume.stride, region.size[0],
                      volume.stride, static_cast<std::int64_t>(part.lowest), part.counts);
                    continue;
                  }
                  for (std::int64_t i = region.begin[0]; i < region.begin[0] + region.size[0]; ++i)
                  {
                    const double v = static_cast<double>(row[i * volume.stride]);
                    if (!std::isfinite(v))
                      continue;
                    const std::int64_t c = part.cell(v);
                    ++part.counts[c];
                    part.minimum[c] = std::min(part.minimum[c], v);
                    part.maximum[c] = std::max(part.maximum[c], v);
                  }
                }
                progress.advance();
              }
              cellCounts.addTo(part.counts);
              if (part.integerCells)
              {
                for (std::size_t c = 0; c < part.counts.size(); ++c)
                  if (part.counts[c] > 0)
                    part.minimum[c] = part.maximum[c] = part.lowest + static_cast<double>(c);
              }
              const std::lock_guard<std::mutex> lock(merging);
              // Counts add and extrema combine in any order: the result does not depend on it.
              for (std::size_t c = 0; c < part.counts.size(); ++c)
              {
                histogram.counts[c] += part.counts[c];
                histogram.minimum[c] = std::min(histogram.minimum[c], part.minimum[c]);
                histogram.maximum[c] = std::max(histogram.maximum[c], part.maximum[c]);
              }
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
