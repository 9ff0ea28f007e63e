// meanVarianceRowExact. The vector form computes count * sumSquares - sum^2 in doubles,
// which is exact while both products stay below 2^52 (as they do for 16-bit CT values in
// boxes of thousands of voxels); lanes that could leave that range take the integer
// formula. Either way the result is meanVarianceFromExactSums's, bit for bit (this file
// has no fused multiply-adds, though here they could not change an exact product).
#include "cpu/box_statistics/MomentRows.h"

#include "cpu/simd/EstimatorLanes.h"

namespace vao
{
namespace detail
{

void meanVarianceRowExactPlain(const std::int64_t* sum, const std::int64_t* sumSquares,
  const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, double* count, double* mean,
  double* variance, std::int64_t begin)
{
  for (std::int64_t i = begin; i < n; ++i)
  {
    const std::int64_t c = countX[i] * countYZ;
    count[i] = static_cast<double>(c);
    double boxVariance = 0.0; // without the squares the mean is the same, the variance dropped
    meanVarianceFromExactSums(sum[i], sumSquares ? sumSquares[i] : 0, c, mean[i], boxVariance);
    if (variance)
      variance[i] = boxVariance;
  }
}

void meanVarianceRowExact(const std::int64_t* sum, const std::int64_t* sumSquares,
  const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, double* count, double* mean,
  double* variance)
{
#if VAO_HAVE_AVX2_TARGET
  const auto plain = [&](std::int64_t end, std::int64_t begin) {
    meanVarianceRowExactPlain(sum, sumSquares, countX, countYZ, end, count, mean, variance, begin);
  };
  if (cpuSimdTier() >= SimdTier::Avx512)
  {
    avx512::meanVarianceRowLanes(sum, sumSquares, countX, countYZ, n, count, mean, variance, plain);
    return;
  }
  if (cpuHasAvx2())
  {
    avx2::meanVarianceRowLanes(sum, sumSquares, countX, countYZ, n, count, mean, variance, plain);
    return;
  }
#endif
  meanVarianceRowExactPlain(sum, sumSquares, countX, countYZ, n, count, mean, variance);
}

} // namespace detail
} // namespace vao
