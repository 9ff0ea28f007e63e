// opennessRow: the Gaussian CDF, Chebyshev and CDF Reconstruction four voxels at a time on
// AVX2, eight on AVX-512 (EstimatorLanes-inl.h). The exact erf and pow are glibc's vector
// forms (libmvec, within 4 ulps of the scalar functions: the float32 openness is the
// scalar's but where the double lies within a few ulps of a float32 rounding boundary, or,
// for the erf, in the far tail where 1 + erf cancels).
// Everything else rounds as the scalar formulas (this file has no fused multiply-adds).
#include "EstimatorRows.h"

#include "EstimatorLanes.h"

#include <type_traits>

namespace vao
{
namespace detail
{

namespace
{

/// Chebyshev and the Gaussian CDF take exact sums directly (opennessFromExactSums).
bool takesExactSums(Method method, const NeighbourhoodRow& row)
{
  return row.sum && (method == Method::Chebyshev || method == Method::GaussianCdf);
}

/// The plain loop over the voxels of [begin, end).
void opennessRange(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness, std::int64_t begin, std::int64_t end)
{
  const bool sums = takesExactSums(method, row);
  for (std::int64_t i = begin; i < end; ++i)
  {
    const double q = query ? query[i] : isoValue;
    if (sums)
    {
      const std::int64_t c = row.countX[i] * row.countYZ;
      openness[i] = static_cast<float>(opennessFromExactSums(method, q, static_cast<double>(c),
        static_cast<double>(row.sum[i]), exactSumsNumerator(row.sum[i], row.sumSquares[i], c), erfMode));
    }
    else
      openness[i] = static_cast<float>(opennessFromStats(method, q, row.stats(i), erfMode));
  }
}

#if VAO_HAVE_AVX2_TARGET
/// The lane loops of the tier's namespace (avx2 or avx512), by method: `sumLanes` on exact
/// sums, else `lanes`.
template <class Lanes, class SumLanes>
void opennessRowVector(Method method, const NeighbourhoodRow& row, const double* query, double isoValue,
  float* openness, Lanes lanes, SumLanes sumLanes)
{
  if (takesExactSums(method, row))
  {
    const auto plain = [&](std::int64_t end, std::int64_t begin) {
      opennessRange(method, ErfMode::Exact, row, query, isoValue, openness, begin, end);
    };
    if (method == Method::Chebyshev)
      sumLanes(std::integral_constant<Method, Method::Chebyshev>(), plain);
    else
      sumLanes(std::integral_constant<Method, Method::GaussianCdf>(), plain);
    return;
  }
  const auto plain = [&](std::int64_t begin) {
    opennessRange(method, ErfMode::Exact, row, query, isoValue, openness, begin, row.size);
  };
  if (method == Method::Chebyshev)
    lanes(std::integral_constant<Method, Method::Chebyshev>(), plain);
  else if (method == Method::CdfReconstruction)
    lanes(std::integral_constant<Method, Method::CdfReconstruction>(), plain);
  else
    lanes(std::integral_constant<Method, Method::GaussianCdf>(), plain);
}
#endif

} // namespace

void opennessRowPlain(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness, std::int64_t begin)
{
  opennessRange(method, erfMode, row, query, isoValue, openness, begin, row.size);
}

bool opennessRowIsVector(Method method, ErfMode erfMode)
{
  const bool chebyshev = method == Method::Chebyshev;
  const bool gaussian = VAO_VECTOR_MATH && method == Method::GaussianCdf && erfMode == ErfMode::Exact;
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
      opennessRowVector(
        method, row, query, isoValue, openness,
        [&](auto m, auto& plain) { avx512::opennessRowLanes<decltype(m)::value>(row, query, isoValue, openness, plain); },
        [&](auto m, auto& plain) {
          avx512::opennessFromExactSumsLanes<decltype(m)::value>(
            row.sum, row.sumSquares, row.countX, row.countYZ, row.size, query, isoValue, openness, plain);
        });
    else
      opennessRowVector(
        method, row, query, isoValue, openness,
        [&](auto m, auto& plain) { avx2::opennessRowLanes<decltype(m)::value>(row, query, isoValue, openness, plain); },
        [&](auto m, auto& plain) {
          avx2::opennessFromExactSumsLanes<decltype(m)::value>(
            row.sum, row.sumSquares, row.countX, row.countYZ, row.size, query, isoValue, openness, plain);
        });
    return;
  }
#endif
  opennessRowPlain(method, erfMode, row, query, isoValue, openness);
}

} // namespace detail
} // namespace vao
