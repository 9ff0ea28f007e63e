// The ranges of an output array (vao/ValueRanges.h): each worker keeps the extremes of its
// chunk, merged under a lock (a few chunks per thread). The loops keep one accumulator per
// lane of a block of kBlock values, so that they vectorise without reassociating
// anything: a minimum, a maximum and a NaN-or-infinity flag are exact in any order.
#include "vao/ValueRanges.h"

#include "cpu/common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

namespace vao
{
namespace
{

constexpr int kBlock = 8;
constexpr float kHugeFloat = std::numeric_limits<float>::infinity();

/// Extremes of a chunk of tuples with NC components (NC divides kBlock, or 0: any count,
/// one tuple at a time), and the extremes of the tuples' squared norms in double, summed
/// component by component in order (as VTK sums them).
template <int NC>
struct ChunkRanges
{
  std::vector<float> lo, hi;
  double squaredLo = std::numeric_limits<double>::infinity();
  double squaredHi = -std::numeric_limits<double>::infinity();
  bool finite = true;

  ChunkRanges(
    const float* values, std::int64_t begin, std::int64_t end, int components, bool withNorm)
    : lo(static_cast<std::size_t>(components), kHugeFloat)
    , hi(static_cast<std::size_t>(components), -kHugeFloat)
  {
    const float* v = values + begin * components;
    const std::int64_t tuples = end - begin;
    std::int64_t t = 0;
    if constexpr (NC > 0)
    {
      // kBlock tuples at a time: the extremes in lanes of kBlock values (lane k holds
      // component k % NC).
      float blockLo[kBlock], blockHi[kBlock], zero[kBlock];
      for (int k = 0; k < kBlock; ++k)
      {
        blockLo[k] = kHugeFloat;
        blockHi[k] = -kHugeFloat;
        zero[k] = 0.0f;
      }
      for (; t + kBlock <= tuples; t += kBlock)
      {
        const float* block = v + t * NC;
        for (int i = 0; i < kBlock * NC; i += kBlock)
        {
          for (int k = 0; k < kBlock; ++k)
          {
            const float x = block[i + k];
            blockLo[k] = x < blockLo[k] ? x : blockLo[k];
            blockHi[k] = x > blockHi[k] ? x : blockHi[k];
            zero[k] += x * 0.0f; // becomes NaN, and stays so, at a NaN or an infinity
          }
        }
      }
      for (int k = 0; k < kBlock; ++k)
      {
        const int c = k % NC;
        this->lo[c] = std::min(this->lo[c], blockLo[k]);
        this->hi[c] = std::max(this->hi[c], blockHi[k]);
        this->finite = this->finite && zero[k] == 0.0f;
      }
    }
    for (; t < tuples; ++t) // the tail, or every tuple when NC is 0
    {
      for (int c = 0; c < components; ++c)
      {
        const float x = v[t * components + c];
        this->lo[c] = x < this->lo[c] ? x : this->lo[c];
        this->hi[c] = x > this->hi[c] ? x : this->hi[c];
        this->finite = this->finite && std::isfinite(x);
      }
    }
    // A second pass for the norms: fused into the one above, the sums' strided loads would
    // stop the extremes' loop from vectorising.
    for (t = 0; withNorm && t < tuples; ++t)
    {
      double sum = 0.0;
      for (int c = 0; c < components; ++c)
      {
        const double d = v[t * components + c];
        sum += d * d;
      }
      this->squaredLo = std::min(this->squaredLo, sum);
      this->squaredHi = std::max(this->squaredHi, sum);
    }
  }
};

template <int NC>
bool rangesOf(
  const float* values, std::int64_t tuples, int components, ValueRanges& ranges, int threads)
{
  const auto nc = static_cast<std::size_t>(components);
  ranges.components.assign(2 * nc, 0.0);
  for (std::size_t c = 0; c < nc; ++c)
  {
    ranges.components[2 * c] = std::numeric_limits<double>::infinity();
    ranges.components[2 * c + 1] = -std::numeric_limits<double>::infinity();
  }
  double squared[2] = { std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity() };
  bool finite = true;
  std::mutex merge;
  const int team = detail::resolveThreadCount(threads);
  detail::parallelFor(tuples, 4 * team, team,
    [&](std::int64_t begin, std::int64_t end)
    {
      const ChunkRanges<NC> chunk(values, begin, end, components, components > 1);
      std::lock_guard<std::mutex> lock(merge);
      finite = finite && chunk.finite;
      for (std::size_t c = 0; c < nc; ++c)
      {
        ranges.components[2 * c] = std::min<double>(ranges.components[2 * c], chunk.lo[c]);
        ranges.components[2 * c + 1] = std::max<double>(ranges.components[2 * c + 1], chunk.hi[c]);
      }
      squared[0] = std::min(squared[0], chunk.squaredLo);
      squared[1] = std::max(squared[1], chunk.squaredHi);
    });
  // Every value finite: squares of floats and their sums stay finite in double.
  // One component: VTK's norm range is the component's range, so none is computed here.
  const double none = std::numeric_limits<double>::quiet_NaN();
  ranges.norm[0] = components > 1 ? std::sqrt(squared[0]) : none;
  ranges.norm[1] = components > 1 ? std::sqrt(squared[1]) : none;
  return finite;
}

} // namespace

bool computeFiniteValueRanges(
  const float* values, std::int64_t tuples, int components, ValueRanges& ranges, int threads)
{
  if (!values || tuples <= 0 || components <= 0)
  {
    return false;
  }
  switch (components)
  {
    case 1:
      return rangesOf<1>(values, tuples, components, ranges, threads);
    case 2:
      return rangesOf<2>(values, tuples, components, ranges, threads);
    case 4:
      return rangesOf<4>(values, tuples, components, ranges, threads);
    case 8:
      return rangesOf<8>(values, tuples, components, ranges, threads);
    default:
      return rangesOf<0>(values, tuples, components, ranges, threads);
  }
}

} // namespace vao
