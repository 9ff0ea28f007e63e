// The separable estimators over a row of neighbourhoods: on AVX2 four voxels at a time,
// on AVX-512 eight (Chebyshev; with glibc's vector erf, exp and log, the Gaussian CDF and CDF
// Reconstruction), elsewhere voxel by voxel.
#pragma once

#include "cpu/box_statistics/BoxEngine.h"

namespace vao
{
namespace detail
{

/// openness[i] = opennessFromStats(method, q_i, row.stats(i), erfMode) as float, for the
/// row's voxels, with q_i = query[i], or isoValue when query is null; for Chebyshev and the
/// Gaussian CDF on a row with exact sums (row.sum), opennessFromExactSums of them instead
/// (the same formulas without the divisions: the mean and variance need not be formed).
/// A raw row (row.raw) gives the same bits from its 16-bit values and 32-bit sums, with
/// q_i = query[i], else its voxel's value where it has them (raw.value), else isoValue.
void opennessRow(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness);

/// The plain loop of opennessRow from voxel `begin` on (the vector forms' tail; tests).
void opennessRowPlain(Method method, ErfMode erfMode, const NeighbourhoodRow& row,
  const double* query, double isoValue, float* openness, std::int64_t begin = 0);

/// True when opennessRow runs four voxels at a time here for this method.
bool opennessRowIsVector(Method method, ErfMode erfMode);

} // namespace detail
} // namespace vao
