// The processor's SIMD tier, detected once, and the cap the tests put on it.
#include "cpu/simd/CpuDispatch.h"

#include <algorithm>
#include <atomic>

namespace vao
{
namespace detail
{
namespace
{

SimdTier detectSimdTier()
{
#if VAO_HAVE_AVX2_TARGET
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
    __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
    __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    return SimdTier::Avx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    return SimdTier::Avx2;
#endif
  return SimdTier::Baseline;
}

std::atomic<int> tierLimit{ static_cast<int>(SimdTier::Avx512) };

} // namespace

SimdTier cpuSimdTier()
{
  static const SimdTier detected = detectSimdTier();
  return static_cast<SimdTier>(
    std::min(static_cast<int>(detected), tierLimit.load(std::memory_order_relaxed)));
}

void limitSimdTier(SimdTier limit)
{
  tierLimit.store(static_cast<int>(limit), std::memory_order_relaxed);
}

} // namespace detail
} // namespace vao
