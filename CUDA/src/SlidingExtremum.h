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

struct MinOp
{
  template <class T>
  T operator()(T a, T b) const
  {
    return b < a ? b : a;
  }
};

struct MaxOp
{
  template <class T>
  T operator()(T a, T b) const
  {
    return a < b ? b : a;
  }
};

/// Scratch buffers of the recurrence, reused across calls by one thread.
template <class T>
struct ExtremumScratch
{
  std::vector<T> prefix;
  std::vector<T> suffix;
};

/// out[k] = op over in[j], j in [i - r, i + r] clipped to [0, n), for i = outBegin + k,
/// k < outCount. in holds n x m values, out outCount x m (x fastest within a lane vector).
/// Blocks of w = 2r + 1 start at 0; a window spans at most two blocks, so it is
/// op(suffix of the first block at lo, prefix of the next at hi).
template <class T, class Op>
void slidingExtremum(const T* in, std::int64_t n, std::int64_t m, std::int64_t r,
  std::int64_t outBegin, std::int64_t outCount, T* out, ExtremumScratch<T>& scratch, Op op)
{
  const std::int64_t w = 2 * r + 1;
  scratch.prefix.resize(static_cast<std::size_t>(n * m));
  scratch.suffix.resize(static_cast<std::size_t>(n * m));
  T* prefix = scratch.prefix.data();
  T* suffix = scratch.suffix.data();
  for (std::int64_t i = 0; i < n; ++i)
  {
    const T* src = in + i * m;
    T* dst = prefix + i * m;
    if (i % w == 0)
    {
      std::copy(src, src + m, dst);
    }
    else
    {
      const T* previous = dst - m;
      for (std::int64_t k = 0; k < m; ++k)
      {
        dst[k] = op(previous[k], src[k]);
      }
    }
  }
  for (std::int64_t i = n - 1; i >= 0; --i)
  {
    const T* src = in + i * m;
    T* dst = suffix + i * m;
    if (i % w == w - 1 || i == n - 1)
    {
      std::copy(src, src + m, dst);
    }
    else
    {
      const T* next = dst + m;
      for (std::int64_t k = 0; k < m; ++k)
      {
        dst[k] = op(src[k], next[k]);
      }
    }
  }
  for (std::int64_t o = 0; o < outCount; ++o)
  {
    const std::int64_t i = outBegin + o;
    const std::int64_t lo = std::max<std::int64_t>(0, i - r);
    const std::int64_t hi = std::min<std::int64_t>(n - 1, i + r);
    T* dst = out + o * m;
    if (lo / w != hi / w)
    {
      const T* a = suffix + lo * m;
      const T* b = prefix + hi * m;
      for (std::int64_t k = 0; k < m; ++k)
      {
        dst[k] = op(a[k], b[k]);
      }
    }
    else if (lo % w == 0)
    {
      std::copy(prefix + hi * m, prefix + hi * m + m, dst); // window starts its block
    }
    else
    {
      std::copy(suffix + lo * m, suffix + lo * m + m, dst); // window ends its block
    }
  }
}

} // namespace detail
} // namespace vao
