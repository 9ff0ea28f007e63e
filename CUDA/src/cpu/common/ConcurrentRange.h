// The range of rows of floats that worker threads write, kept as they write them (the
// extremes of each row, merged by compare-and-swap), so that the output's range needs no
// second pass over it.
#pragma once

#include "VolumeAccess.h"
#include "vao/AmbientOcclusion.h"

#include <atomic>
#include <cstdint>
#include <limits>

namespace vao
{
namespace detail
{

/// The lowest and highest of n values; false when one is not finite (then lo and hi are
/// unspecified). Eight at a time on AVX2, sixteen on AVX-512.
bool rowExtremes(const float* v, std::int64_t n, float& lo, float& hi);

class ConcurrentRange
{
public:
  /// Takes in n values; any thread.
  void add(const float* v, std::int64_t n)
  {
    float lo = kHuge, hi = -kHuge;
    if (!rowExtremes(v, n, lo, hi))
      this->Finite.store(false, std::memory_order_relaxed);
    float seen = this->Lowest.load(std::memory_order_relaxed);
    while (lo < seen && !this->Lowest.compare_exchange_weak(seen, lo, std::memory_order_relaxed))
    {
    }
    seen = this->Highest.load(std::memory_order_relaxed);
    while (hi > seen && !this->Highest.compare_exchange_weak(seen, hi, std::memory_order_relaxed))
    {
    }
  }

  /// The range of every value added (after the threads are joined): known when at least
  /// one value came and all were finite.
  OutputRange result() const
  {
    OutputRange r;
    r.lowest = this->Lowest.load();
    r.highest = this->Highest.load();
    r.known = this->Finite.load() && r.lowest <= r.highest;
    return r;
  }

private:
  static constexpr float kHuge = std::numeric_limits<float>::infinity();
  std::atomic<float> Lowest{ kHuge };
  std::atomic<float> Highest{ -kHuge };
  std::atomic<bool> Finite{ true };
};

/// Runs pass(tag, seen) with `tag` a value of the volume's scalar type (the pass reads the
/// volume as that type), `seen` keeping the range of what the pass writes (null when `range`
/// is null, so that nothing is kept): Status::cancelled when the pass returns false, else
/// success with that range in `range`.
template <class TypedPass>
Status keepingOutputRange(ScalarType type, OutputRange* range, TypedPass&& pass)
{
  ConcurrentRange seen;
  ConcurrentRange* kept = range ? &seen : nullptr;
  if (!dispatchScalarType(type, [&](auto tag) { return pass(tag, kept); }))
    return Status::cancelled();
  if (range)
    *range = seen.result();
  return Status::success();
}

} // namespace detail
} // namespace vao
