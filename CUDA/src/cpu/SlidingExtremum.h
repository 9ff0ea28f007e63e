// Van Herk / Gil-Werman running minimum and maximum: 3 comparisons per element whatever
// the window, over a sequence of n "lanes" vectors (m contiguous values each), windows
// clipped to the sequence. m = 1 is a plain 1-D signal (a row along x); m = row length
// runs the same recurrence along y or z on whole rows at once, which vectorises.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{

/// Where each output window's two partial results sit, for one (n, r, outBegin, outCount):
/// out[o] = op(parts[first[o]], parts[second[o]]) with parts = [prefix | suffix]. Computed
/// once and reused for every lane vector and row of the same shape, so the per-element
/// work has no integer division.
struct WindowPlan
{
  std::int64_t n = -1, r = -1, outBegin = -1, outCount = -1;
  std::vector<std::int64_t> first, second;

  void prepare(std::int64_t length, std::int64_t radius, std::int64_t begin, std::int64_t count)
  {
    if (length == n && radius == r && begin == outBegin && count == outCount)
    {
      return;
    }
    n = length, r = radius, outBegin = begin, outCount = count;
    first.resize(static_cast<std::size_t>(count));
    second.resize(static_cast<std::size_t>(count));
    const std::int64_t w = 2 * r + 1;
    for (std::int64_t o = 0; o < count; ++o)
    {
      const std::int64_t i = begin + o;
      const std::int64_t lo = std::max<std::int64_t>(0, i - r);
      const std::int64_t hi = std::min<std::int64_t>(n - 1, i + r);
      if (lo / w != hi / w)
      {
        first[o] = n + lo; // suffix of the first block at lo
        second[o] = hi;    // prefix of the next block at hi
      }
      else if (lo % w == 0)
      {
        first[o] = second[o] = hi; // the window starts its block: a prefix
      }
      else
      {
        first[o] = second[o] = n + lo; // the window ends its block (or the data): a suffix
      }
    }
  }
};

/// Scratch buffers of the recurrence, reused across calls by one thread.
template <class T>
struct ExtremumScratch
{
  std::vector<T> minParts; // prefix (n x m) then suffix (n x m) of the minimum
  std::vector<T> maxParts; // the same for the maximum
  WindowPlan plan;
};

/// outMin[k] = min over inMin[j] and outMax[k] = max over inMax[j], j in [i - r, i + r]
/// clipped to [0, n), for i = outBegin + k, k < outCount. The inputs hold n x m values, the
/// outputs outCount x m (x fastest within a lane vector). Blocks of w = 2r + 1 start at 0;
/// a window spans at most two blocks, so it combines the suffix of the first block at lo
/// with the prefix of the next at hi. Both extrema go in one sweep (inMin == inMax on the
/// first pass, the previous pass's minimum and maximum after it).
template <class T>
void slidingMinMax(const T* inMin, const T* inMax, std::int64_t n, std::int64_t m, std::int64_t r,
  std::int64_t outBegin, std::int64_t outCount, T* outMin, T* outMax, ExtremumScratch<T>& scratch)
{
  const std::int64_t w = 2 * r + 1;
  scratch.minParts.resize(static_cast<std::size_t>(2 * n * m));
  scratch.maxParts.resize(static_cast<std::size_t>(2 * n * m));
  scratch.plan.prepare(n, r, outBegin, outCount);
  T* preMin = scratch.minParts.data();
  T* sufMin = preMin + n * m;
  T* preMax = scratch.maxParts.data();
  T* sufMax = preMax + n * m;
  for (std::int64_t blockStart = 0; blockStart < n; blockStart += w)
  {
    const std::int64_t blockEnd = std::min(n, blockStart + w);
    // The first element of a block starts both running results; the rest extend them.
    std::copy(inMin + blockStart * m, inMin + (blockStart + 1) * m, preMin + blockStart * m);
    std::copy(inMax + blockStart * m, inMax + (blockStart + 1) * m, preMax + blockStart * m);
    for (std::int64_t i = blockStart + 1; i < blockEnd; ++i)
    {
      for (std::int64_t k = 0; k < m; ++k)
      {
        preMin[i * m + k] = std::min(preMin[(i - 1) * m + k], inMin[i * m + k]);
        preMax[i * m + k] = std::max(preMax[(i - 1) * m + k], inMax[i * m + k]);
      }
    }
    std::copy(inMin + (blockEnd - 1) * m, inMin + blockEnd * m, sufMin + (blockEnd - 1) * m);
    std::copy(inMax + (blockEnd - 1) * m, inMax + blockEnd * m, sufMax + (blockEnd - 1) * m);
    for (std::int64_t i = blockEnd - 2; i >= blockStart; --i)
    {
      for (std::int64_t k = 0; k < m; ++k)
      {
        sufMin[i * m + k] = std::min(sufMin[(i + 1) * m + k], inMin[i * m + k]);
        sufMax[i * m + k] = std::max(sufMax[(i + 1) * m + k], inMax[i * m + k]);
      }
    }
  }
  const std::int64_t* first = scratch.plan.first.data();
  const std::int64_t* second = scratch.plan.second.data();
  for (std::int64_t o = 0; o < outCount; ++o)
  {
    const std::int64_t a = first[o] * m, b = second[o] * m;
    for (std::int64_t k = 0; k < m; ++k)
    {
      outMin[o * m + k] = std::min(preMin[a + k], preMin[b + k]);
      outMax[o * m + k] = std::max(preMax[a + k], preMax[b + k]);
    }
  }
}

} // namespace detail
} // namespace vao
