// opennessRow: the Gaussian CDF, Chebyshev and CDF Reconstruction four voxels at a time on
// AVX2, eight on AVX-512 (EstimatorLanes-inl.h). The exact erf, and the exp and log that
// form CDF Reconstruction's power, are glibc's vector forms (libmvec, within 4 ulps of the
// scalar functions: the float32 openness is the scalar's but where the double lies within
// a few ulps (for the power, |beta log t| more) of a float32 rounding boundary, or, for
// the erf, in the far tail where 1 + erf cancels).
// Everything else rounds as the scalar formulas (this file has no fused multiply-adds).
#include "cpu/box_statistics/EstimatorRows.h"

#include "cpu/simd/EstimatorLanes.h"

namespace vao
{
namespace detail
{

namespace
{

/// Chebyshev and the Gaussian CDF take exact sums directly (opennessFromExactSums).
bool takesExactSums(Method method, const NeighbourhoodRow& row)
{
  return (row.sum || row.raw.sum) && (method == Method::Chebyshev || method == Method::GaussianCdf);
}

/// Box i's exact sum: a row's 64-bit one, or a raw row's 32-bit one.
std::int64_t exactSum(const NeighbourhoodRow& row, std::int64_t i)
{
  return row.raw.sum ? row.raw.sum[i] : row.sum[i];
}

/// Value i of a raw row's array p (NeighbourhoodRow::raw), as a double.
double rawAt(const RawRow& raw, const void* p, std::int64_t i)
{
  return raw.type == ScalarType::Int16 ? static_cast<const std::int16_t*>(p)[i]
                                       : static_cast<const std::uint16_t*>(p)[i];
}

/// The statistics of a raw row's box i, as the widening passes and meanVarianceRowExact
/// give them (the mean alone of the moments, as CDF Reconstruction asks).
NeighbourhoodStats rawStats(const NeighbourhoodRow& row, std::int64_t i)
{
  NeighbourhoodStats s{ 0.0, 0.0, rawAt(row.raw, row.raw.minimum, i),
    rawAt(row.raw, row.raw.maximum, i), row.roundingVariance };
  double variance = 0.0;
  meanVarianceFromExactSums(row.raw.sum[i], 0, row.countX[i] * row.countYZ, s.mean, variance);
  return s;
}

/// The plain loop over the voxels of [begin, end).
void opennessRange(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness, std::int64_t begin, std::int64_t end)
{
  const bool sums = takesExactSums(method, row);
  for (std::int64_t i = begin; i < end; ++i)
  {
    const double q = query ? query[i] : row.raw.value ? rawAt(row.raw, row.raw.value, i) : isoValue;
    if (sums)
    {
      const std::int64_t c = row.countX[i] * row.countYZ;
      const std::int64_t sum = exactSum(row, i);
      openness[i] = static_cast<float>(opennessFromExactSums(method, q, static_cast<double>(c),
        static_cast<double>(sum), exactSumsNumerator(sum, row.sumSquares[i], c), erfMode));
    }
    else
      openness[i] = static_cast<float>(
        opennessFromStats(method, q, row.raw.sum ? rawStats(row, i) : row.stats(i), erfMode));
  }
}

#if VAO_HAVE_AVX2_TARGET
/// The row loops of a width (avx2::RowLoops or avx512::RowLoops) by method: on exact sums
/// where the row has them for it, else on its statistics, with the queries of lanesQuery
/// (query, or a raw row's own values where query is null) or isoValue.
template <class Loops, class Q>
void opennessRowVectorFrom(Method method, const NeighbourhoodRow& row, const double* query,
  const Q* lanesQuery, double isoValue, float* openness)
{
  if (takesExactSums(method, row))
  {
    const auto plain = [&](std::int64_t end, std::int64_t begin)
    { opennessRange(method, ErfMode::Exact, row, query, isoValue, openness, begin, end); };
    if (method == Method::Chebyshev)
      Loops::template onExactSums<Method::Chebyshev>(row, lanesQuery, isoValue, openness, plain);
    else
      Loops::template onExactSums<Method::GaussianCdf>(row, lanesQuery, isoValue, openness, plain);
    return;
  }
  const auto plain = [&](std::int64_t begin)
  { opennessRange(method, ErfMode::Exact, row, query, isoValue, openness, begin, row.size); };
#if VAO_VECTOR_MATH
  if (row.raw.sum) // CDF Reconstruction's (RowContents::raw)
  {
    if (row.raw.type == ScalarType::Int16)
      Loops::template cdfReconstructionOnRaw<std::int16_t>(
        row, lanesQuery, isoValue, openness, plain);
    else
      Loops::template cdfReconstructionOnRaw<std::uint16_t>(
        row, lanesQuery, isoValue, openness, plain);
    return;
  }
#endif
  if (method == Method::Chebyshev)
    Loops::template onStatistics<Method::Chebyshev>(row, lanesQuery, isoValue, openness, plain);
  else if (method == Method::CdfReconstruction)
    Loops::template onStatistics<Method::CdfReconstruction>(
      row, lanesQuery, isoValue, openness, plain);
  else
    Loops::template onStatistics<Method::GaussianCdf>(row, lanesQuery, isoValue, openness, plain);
}

/// opennessRowVectorFrom with a raw row's own values as the queries where query is null.
template <class Loops>
void opennessRowVector(
  Method method, const NeighbourhoodRow& row, const double* query, double isoValue, float* openness)
{
  if (query || !row.raw.value)
    opennessRowVectorFrom<Loops>(method, row, query, query, isoValue, openness);
  else if (row.raw.type == ScalarType::Int16)
    opennessRowVectorFrom<Loops>(
      method, row, query, static_cast<const std::int16_t*>(row.raw.value), isoValue, openness);
  else
    opennessRowVectorFrom<Loops>(
      method, row, query, static_cast<const std::uint16_t*>(row.raw.value), isoValue, openness);
}
#endif

} // namespace

void opennessRowPlain(Method method, ErfMode erfMode, const NeighbourhoodRow& row,
  const double* query, double isoValue, float* openness, std::int64_t begin)
{
  opennessRange(method, erfMode, row, query, isoValue, openness, begin, row.size);
}

bool opennessRowIsVector(Method method, ErfMode erfMode)
{
  const bool chebyshev = method == Method::Chebyshev;
  const bool gaussian =
    VAO_VECTOR_MATH && method == Method::GaussianCdf && erfMode == ErfMode::Exact;
  const bool reconstruction = VAO_VECTOR_MATH && method == Method::CdfReconstruction;
  return cpuHasAvx2() && (chebyshev || gaussian || reconstruction);
}

void opennessRow(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness)
{
#if VAO_HAVE_AVX2_TARGET
  if (opennessRowIsVector(method, erfMode))
  {
    if (cpuSimdTier() >= SimdTier::Avx512)
      opennessRowVector<avx512::RowLoops>(method, row, query, isoValue, openness);
    else
      opennessRowVector<avx2::RowLoops>(method, row, query, isoValue, openness);
    return;
  }
#endif
  opennessRowPlain(method, erfMode, row, query, isoValue, openness);
}

} // namespace detail
} // namespace vao
