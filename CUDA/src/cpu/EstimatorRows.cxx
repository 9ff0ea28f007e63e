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

void opennessRowPlain(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness, std::int64_t begin)
{
  for (std::int64_t i = begin; i < row.size; ++i)
  {
    const double q = query ? query[i] : isoValue;
    openness[i] = static_cast<float>(opennessFromStats(method, q, row.stats(i), erfMode));
  }
}

#if VAO_HAVE_AVX2_TARGET
namespace
{

/// opennessRowLanes of the tier's namespace (avx2 or avx512), by method.
template <class Lanes>
void opennessRowVector(Method method, const NeighbourhoodRow& row, const double* query, double isoValue,
  float* openness, Lanes lanes)
{
  const auto plain = [&](std::int64_t begin) {
    opennessRowPlain(method, ErfMode::Exact, row, query, isoValue, openness, begin);
  };
  if (method == Method::Chebyshev)
    lanes(std::integral_constant<Method, Method::Chebyshev>(), plain);
  else if (method == Method::CdfReconstruction)
    lanes(std::integral_constant<Method, Method::CdfReconstruction>(), plain);
  else
    lanes(std::integral_constant<Method, Method::GaussianCdf>(), plain);
}

} // namespace
#endif

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
      opennessRowVector(method, row, query, isoValue, openness, [&](auto m, auto& plain) {
        avx512::opennessRowLanes<decltype(m)::value>(row, query, isoValue, openness, plain);
      });
    else
      opennessRowVector(method, row, query, isoValue, openness, [&](auto m, auto& plain) {
        avx2::opennessRowLanes<decltype(m)::value>(row, query, isoValue, openness, plain);
      });
    return;
  }
#endif
  opennessRowPlain(method, erfMode, row, query, isoValue, openness);
}

} // namespace detail
} // namespace vao
