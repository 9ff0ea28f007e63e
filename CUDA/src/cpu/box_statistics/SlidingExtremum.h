// Van Herk / Gil-Werman running minimum and maximum: 3 comparisons per element whatever
// the window, over a sequence of n "lanes" vectors (m contiguous values each), windows
// clipped to the sequence. m = 1 is a plain 1-D signal (a row along x); m = row length
// runs the same recurrence along y or z on whole rows at once, which vectorises.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

/// Where each output window's two partial results sit, for one (n, r, outBegin, outCount):
/// out[o] = op(parts[first[o]], parts[second[o]]) with parts = [prefix | suffix], and
/// lo[o], the window's first position, where the suffix it takes is known. Computed once
/// and reused for every lane vector and row of the same shape, so the per-element work has
/// no integer division.
struct WindowPlan
{
  std::int64_t n = -1, r = -1, outBegin = -1, outCount = -1;
  std::vector<std::int64_t> first, second, lo;

  void prepare(std::int64_t length, std::int64_t radius, std::int64_t begin, std::int64_t count)
  {
    if (length == n && radius == r && begin == outBegin && count == outCount)
    {
      return;
    }
    n = length, r = radius, outBegin = begin, outCount = count;
    first.resize(static_cast<std::size_t>(count));
    second.resize(static_cast<std::size_t>(count));
    lo.resize(static_cast<std::size_t>(count));
    const std::int64_t w = 2 * r + 1;
    for (std::int64_t o = 0; o < count; ++o)
    {
      const std::int64_t i = begin + o;
      const std::int64_t lo = std::max<std::int64_t>(0, i - r);
      const std::int64_t hi = std::min<std::int64_t>(n - 1, i + r);
      this->lo[o] = lo;
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
  std::vector<T> minParts; // prefix (n x m) then the running suffix (m) of the minimum
  std::vector<T> maxParts; // the same for the maximum
  WindowPlan plan;
};

/// The steps of the recurrence on m lanes: plain loops and conditionals, which the row
/// loop's target vectorises (CpuDispatch.h); no inline library function is compiled for
/// AVX2 here.
template <class T>
struct LaneLoops
{
  /// A block's first element starts both running results.
  static VAO_ALWAYS_INLINE void start(
    const T* lo, const T* hi, T* __restrict runMin, T* __restrict runMax, std::int64_t m)
  {
    for (std::int64_t k = 0; k < m; ++k)
    {
      runMin[k] = lo[k];
      runMax[k] = hi[k];
    }
  }

  /// One step of the running results: runMin = min(lo, prevMin), runMax = max(hi, prevMax).
  static VAO_ALWAYS_INLINE void extend(const T* lo, const T* hi, const T* prevMin, const T* prevMax,
    T* __restrict runMin, T* __restrict runMax, std::int64_t m)
  {
    for (std::int64_t k = 0; k < m; ++k)
    {
      runMin[k] = lo[k] < prevMin[k] ? lo[k] : prevMin[k];
      runMax[k] = prevMax[k] < hi[k] ? hi[k] : prevMax[k];
    }
  }

  /// The suffix one position further: sufMin = min(lo, sufMin), sufMax = max(hi, sufMax).
  static VAO_ALWAYS_INLINE void extendInPlace(
    const T* lo, const T* hi, T* sufMin, T* sufMax, std::int64_t m)
  {
    for (std::int64_t k = 0; k < m; ++k)
    {
      sufMin[k] = lo[k] < sufMin[k] ? lo[k] : sufMin[k];
      sufMax[k] = sufMax[k] < hi[k] ? hi[k] : sufMax[k];
    }
  }

  /// An output: om = min(minA, minB), ox = max(maxA, maxB).
  static VAO_ALWAYS_INLINE void combine(const T* minA, const T* minB, const T* maxA, const T* maxB,
    T* __restrict om, T* __restrict ox, std::int64_t m)
  {
    for (std::int64_t k = 0; k < m; ++k)
    {
      om[k] = minB[k] < minA[k] ? minB[k] : minA[k];
      ox[k] = maxA[k] < maxB[k] ? maxB[k] : maxA[k];
    }
  }
};

#if defined(__GNUC__) || defined(__clang__)
/// 16 values of a 16-bit type as one 32-byte vector (the compilers' vector extension).
template <class T>
struct SixteenValues;
template <>
struct SixteenValues<std::int16_t>
{
  typedef std::int16_t type __attribute__((vector_size(32)));
};
template <>
struct SixteenValues<std::uint16_t>
{
  typedef std::uint16_t type __attribute__((vector_size(32)));
};

/// LaneLoops' steps on exactly 16 lanes of 16-bit values (the x pass's rows, BoxExtrema.h):
/// one vector each, as the loops over a run-time m compile to a vector step wrapped in
/// the checks and tails of a loop, which on 16 lanes cost more than the step.
template <class T>
struct SixteenLanes
{
  using V = typename SixteenValues<T>::type;
  // Pointers in and out, so that no function passes a vector by value (whose ABI differs
  // between the targets the row loop is built for).
  /// out = min(a, b), or max(a, b) with Greater.
  template <bool Greater>
  static VAO_ALWAYS_INLINE void pick(const T* a, const T* b, T* out)
  {
    V x, y;
    __builtin_memcpy(&x, a, sizeof x);
    __builtin_memcpy(&y, b, sizeof y);
    V result;
    if constexpr (Greater)
      result = x < y ? y : x;
    else
      result = x < y ? x : y;
    __builtin_memcpy(out, &result, sizeof result);
  }
  static VAO_ALWAYS_INLINE void lesser(const T* a, const T* b, T* out) { pick<false>(a, b, out); }
  static VAO_ALWAYS_INLINE void greater(const T* a, const T* b, T* out) { pick<true>(a, b, out); }

  static VAO_ALWAYS_INLINE void start(const T* lo, const T* hi, T* runMin, T* runMax, std::int64_t)
  {
    __builtin_memcpy(runMin, lo, sizeof(V));
    __builtin_memcpy(runMax, hi, sizeof(V));
  }
  static VAO_ALWAYS_INLINE void extend(const T* lo, const T* hi, const T* prevMin, const T* prevMax,
    T* runMin, T* runMax, std::int64_t)
  {
    lesser(lo, prevMin, runMin);
    greater(hi, prevMax, runMax);
  }
  static VAO_ALWAYS_INLINE void extendInPlace(
    const T* lo, const T* hi, T* sufMin, T* sufMax, std::int64_t)
  {
    lesser(lo, sufMin, sufMin);
    greater(hi, sufMax, sufMax);
  }
  static VAO_ALWAYS_INLINE void combine(
    const T* minA, const T* minB, const T* maxA, const T* maxB, T* om, T* ox, std::int64_t)
  {
    lesser(minA, minB, om);
    greater(maxA, maxB, ox);
  }
};
#endif

/// The recurrence and the combination of slidingMinMax on prepared buffers, a row loop
/// (CpuDispatch.h) whose element-wise steps are Steps' (LaneLoops, or SixteenLanes).
template <class T, class Steps = LaneLoops<T>>
struct ExtremumPasses
{
  /// The prefixes of every block forward, then each block's suffix backward, kept as one
  /// running lane vector: an output is written at its window's first position, where the
  /// suffix it takes is the running one, so the suffixes are never stored. Outputs sit at
  /// or after that position, so they may overwrite input already read.
  static VAO_ALWAYS_INLINE void run(const T* inMin, const T* inMax, std::int64_t inStride,
    std::int64_t n, std::int64_t m, std::int64_t w, T* preMin, T* sufMin, T* preMax, T* sufMax,
    const std::int64_t* first, const std::int64_t* second, const std::int64_t* lo,
    std::int64_t outCount, T* outMin, T* outMax, std::int64_t outStride)
  {
    for (std::int64_t blockStart = 0; blockStart < n; blockStart += w)
    {
      const std::int64_t blockEnd = blockStart + w < n ? blockStart + w : n;
      // The first element of a block starts both running results; the rest extend them.
      Steps::start(inMin + blockStart * inStride, inMax + blockStart * inStride,
        preMin + blockStart * m, preMax + blockStart * m, m);
      for (std::int64_t i = blockStart + 1; i < blockEnd; ++i)
      {
        Steps::extend(inMin + i * inStride, inMax + i * inStride, preMin + (i - 1) * m,
          preMax + (i - 1) * m, preMin + i * m, preMax + i * m, m);
      }
    }
    std::int64_t o = outCount - 1;
    for (std::int64_t blockStart = (n - 1) / w * w; blockStart >= 0; blockStart -= w)
    {
      const std::int64_t last = (blockStart + w < n ? blockStart + w : n) - 1;
      for (std::int64_t i = last; i >= blockStart; --i)
      {
        if (i == last)
          Steps::start(inMin + i * inStride, inMax + i * inStride, sufMin, sufMax, m);
        else
          Steps::extendInPlace(inMin + i * inStride, inMax + i * inStride, sufMin, sufMax, m);
        for (; o >= 0 && lo[o] == i; --o)
        {
          // first and second index [prefix | suffix]: a suffix reference is the running one.
          const T* minA = first[o] < n ? preMin + first[o] * m : sufMin;
          const T* minB = second[o] < n ? preMin + second[o] * m : sufMin;
          const T* maxA = first[o] < n ? preMax + first[o] * m : sufMax;
          const T* maxB = second[o] < n ? preMax + second[o] * m : sufMax;
          Steps::combine(minA, minB, maxA, maxB, outMin + o * outStride, outMax + o * outStride, m);
        }
      }
    }
  }
};

/// outMin[k] = min over inMin[j] and outMax[k] = max over inMax[j], j in [i - r, i + r]
/// clipped to [0, n), for i = outBegin + k, k < outCount. The inputs hold n x m values, the
/// outputs outCount x m (x fastest within a lane vector). Blocks of w = 2r + 1 start at 0;
/// a window spans at most two blocks, so it combines the suffix of the first block at lo
/// with the prefix of the next at hi. Both extrema go in one sweep (inMin == inMax on the
/// first pass, the previous pass's minimum and maximum after it). Sequence position i of
/// the input starts at i * inStride, of the output at o * outStride (default: m, packed);
/// the output may overwrite the input (each output goes after its window has been read).
template <class T>
void slidingMinMax(const T* inMin, const T* inMax, std::int64_t n, std::int64_t m, std::int64_t r,
  std::int64_t outBegin, std::int64_t outCount, T* outMin, T* outMax, ExtremumScratch<T>& scratch,
  std::int64_t inStride = -1, std::int64_t outStride = -1)
{
  scratch.minParts.resize(static_cast<std::size_t>((n + 1) * m));
  scratch.maxParts.resize(static_cast<std::size_t>((n + 1) * m));
  scratch.plan.prepare(n, r, outBegin, outCount);
  T* preMin = scratch.minParts.data();
  T* preMax = scratch.maxParts.data();
  // AVX2 at most: AVX-512 brings these compare-and-store loops nothing.
  const auto passes = [&](auto steps)
  {
    runRows<ExtremumPasses<T, decltype(steps)>>(cpuSimdTierUpTo(SimdTier::Avx2), inMin, inMax,
      inStride < 0 ? m : inStride, n, m, 2 * r + 1, preMin, preMin + n * m, preMax, preMax + n * m,
      scratch.plan.first.data(), scratch.plan.second.data(), scratch.plan.lo.data(), outCount,
      outMin, outMax, outStride < 0 ? m : outStride);
  };
#if defined(__GNUC__) || defined(__clang__)
  if constexpr (std::is_same<T, std::int16_t>::value || std::is_same<T, std::uint16_t>::value)
    if (m == 16)
    {
      passes(SixteenLanes<T>());
      return;
    }
#endif
  passes(LaneLoops<T>());
}

} // namespace detail
} // namespace vao
