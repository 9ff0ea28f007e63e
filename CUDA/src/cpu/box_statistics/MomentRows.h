// The mean and variance of a row of boxes from exact integer sums (meanVarianceFromExactSums
// of Estimators.h), four boxes at a time on AVX2.
#pragma once

#include <cstdint>

namespace vao
{
namespace detail
{

/// For the n boxes of countX[i] * countYZ voxels with exact sums sum[i] and sumSquares[i]:
/// count[i], mean[i] and variance[i] as meanVarianceFromExactSums gives them, bit for bit;
/// count and mean alone where sumSquares is null (variance may be null then).
void meanVarianceRowExact(const std::int64_t* sum, const std::int64_t* sumSquares,
  const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, double* count, double* mean,
  double* variance);

/// The plain loop of meanVarianceRowExact from box `begin` on.
void meanVarianceRowExactPlain(const std::int64_t* sum, const std::int64_t* sumSquares,
  const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, double* count, double* mean,
  double* variance, std::int64_t begin = 0);

} // namespace detail
} // namespace vao
