// The openness estimators of docs/methods.md, written once for host and device.
//
// Every function here is a pure formula on the statistics of one neighbourhood, so the
// CPU path and the CUDA kernels (src/cuda/common/Pipeline.h) include this header and call
// the same code. Openness O = P(v <= q) over the neighbourhood: 1 = fully open, 0 = fully occluded.
#pragma once

#include <cmath>
#include <type_traits>

#if defined(__CUDACC__)
#define VAO_HD __host__ __device__ inline
#else
#define VAO_HD inline
#endif

namespace vao
{

enum class Method : int
{
  CdfReconstruction = 0,
  GaussianCdf = 1,
  Chebyshev = 2,
  ExactBox = 3,
  ExactSphere = 4,
  HistogramCdf = 5,
  TransferFunction = 6, // 1 - the box's mean opacity (vao/TransferFunction.h)
  ExactRays = 7,        // ray-cast AO through the opacity (vao/RayCasting.h), the reference
  Rays = 8,             // an estimate of ExactRays' AO whose cost grows like log R
};

/// True for the methods that cast rays through the opacity (vao/RayCasting.h).
VAO_HD bool isRayMethod(Method method)
{
  return method == Method::ExactRays || method == Method::Rays;
}

enum class ErfMode : int
{
  Exact = 0,
  Winitzki = 1,
};

/// True for the methods estimated from separable statistics (no O(R^3) reference).
VAO_HD bool isSeparableMethod(Method method)
{
  return method == Method::CdfReconstruction || method == Method::GaussianCdf ||
    method == Method::Chebyshev;
}

/// Statistics of one clipped box neighbourhood, as the estimators consume them.
struct NeighbourhoodStats
{
  double mean;
  double variance; // population variance E[v^2] - mean^2, clamped at 0
  double minimum;
  double maximum;
  // The variance that rounding alone can give a flat box (sumRoundingVariance; 0 for
  // exact sums): at or below it the statistics cannot tell the box from a flat one.
  double roundingVariance = 0.0;
};

/// Ulps of deviation^2 that streamed double sums may be off by, in variance: the running
/// sums of (v - shift) and (v - shift)^2 add and subtract every slice, row and voxel that
/// enters or leaves a window, so their rounding grows with the largest |v - shift| of the
/// data, not with the box's own mean. The worst measured is 4.4 ulps (the scenes of
/// test_flat_backgrounds.cxx, which prints it) and 0.06 ulps on 200 x 200 x 400 doubles
/// with scattered 1e12 voxels: 1024 leaves a wide margin, and at 2.3e-13 deviation^2 it
/// stays far below any variance the sums could resolve.
constexpr double kSumRoundingUlps = 1024.0;

/// The spacing of doubles at 1 (DBL_EPSILON, here without <cfloat> for device code).
constexpr double kDoubleUlp = 2.220446049250313e-16;

/// The variance rounding can give a flat box when every value of the data lies within
/// `deviation` of the shift its double sums were taken about.
VAO_HD double sumRoundingVariance(double deviation)
{
  return kSumRoundingUlps * kDoubleUlp * deviation * deviation;
}

/// The flat-neighbourhood rule (docs/methods.md, flat boxes), with no allowance beyond
/// rounding: a box is flat where its variance is at most what the rounding of its sums can
/// give a flat box (roundingVariance: 0 for exact sums, sumRoundingVariance for double
/// sums, which scales with the data's spread about the shift). A threshold relative to mu^2
/// or to 1 would break the estimators' invariance to offset and scale: CT values stored
/// with an offset of 1e9 (mu^2 ~ 1e18) or in units of 1e-10 (every variance below 1e-14)
/// would make every box flat, and every openness 0 or 1.
VAO_HD bool isFlatVariance(double variance, double roundingVariance = 0.0)
{
  return variance <= roundingVariance;
}

/// The variance a box reports (the Variance output): 0 where the flat rule calls the box
/// flat, so that flat regions read exactly 0 whatever the data's type (double sums leave
/// rounding there, 1e-13 on values near 7).
VAO_HD double reportedVariance(double variance, double roundingVariance)
{
  return isFlatVariance(variance, roundingVariance) ? 0.0 : variance;
}

/// How far below its mean a flat neighbourhood's value can lie once the mean is rounded,
/// relative to |mu|: float32 precision, which the moment pyramid's levels are stored in
/// (a mean of sums is a few double ulps off). Relative to |mu| alone, so that it scales
/// with the data: an iso value within this of a flat region's value counts as that value.
constexpr double kFlatSpread = 1e-7;

/// flatOpenness given the rounding spread of its sums (flatRoundingSpread): callers that
/// query one set of sums many times take the square root once.
VAO_HD double flatOpennessWithin(double query, double mean, double roundingSpread)
{
  const double relative = kFlatSpread * (mean < 0.0 ? -mean : mean);
  return query >= mean - (roundingSpread > relative ? roundingSpread : relative) ? 1.0 : 0.0;
}

/// How far below its mean the rounding of double sums can put a flat value (0 for exact
/// sums, which skip the square root: flat boxes are most of many volumes).
VAO_HD double flatRoundingSpread(double roundingVariance)
{
  return roundingVariance > 0.0 ? sqrt(roundingVariance * kSumRoundingUlps * kDoubleUlp) : 0.0;
}

/// The exact answer on a flat neighbourhood, which every estimator returns there:
/// O = (q >= mu). The computed mu carries the rounding of streamed sums (the CPU's and the
/// GPU's differ by a few ulps), so a query equal to the common value may land a hair below
/// it. A query within the flat spread of mu, or within the rounding of a mean of double
/// sums (kSumRoundingUlps ulps of the data's largest deviation, which roundingVariance
/// squares), is one of the neighbourhood's values: q >= mu. An iso value closer than
/// that to a flat region's value cannot be told from it.
VAO_HD double flatOpenness(double query, double mean, double roundingVariance = 0.0)
{
  return flatOpennessWithin(query, mean, flatRoundingSpread(roundingVariance));
}

VAO_HD double clamp01(double x)
{
  return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

/// Winitzki's closed-form approximation of erf with a = 8(pi - 3) / (3 pi (4 - pi)) ~ 0.140:
/// max abs error 3.3e-4 (measured on [-6, 6]; the 1.2e-4 often quoted is for a = 0.147).
VAO_HD double erfWinitzki(double x)
{
  constexpr double pi = 3.14159265358979323846;
  constexpr double a = 8.0 * (pi - 3.0) / (3.0 * pi * (4.0 - pi));
  const double x2 = x * x;
  const double inner = 1.0 - exp(-x2 * (4.0 / pi + a * x2) / (1.0 + a * x2));
  const double magnitude = sqrt(inner > 0.0 ? inner : 0.0);
  return x < 0.0 ? -magnitude : magnitude;
}

/// Ruiz et al. section 3.2: O = t^beta with t = (q - vmin)/(vmax - vmin) and
/// beta = (mu - vmin)/(vmax - mu). Flat when vmax == vmin.
VAO_HD double opennessCdfReconstruction(double query, const NeighbourhoodStats& s)
{
  if (s.maximum <= s.minimum)
  {
    return query >= s.minimum ? 1.0 : 0.0; // every value is vmin, which is exact
  }
  const double t = (query - s.minimum) / (s.maximum - s.minimum);
  if (t >= 1.0)
  {
    return 1.0;
  }
  if (t <= 0.0)
  {
    return 0.0;
  }
  // The mean comes from rounded sums and may stray a hair outside [vmin, vmax].
  const double mean = s.mean < s.minimum ? s.minimum : (s.mean > s.maximum ? s.maximum : s.mean);
  if (mean >= s.maximum)
  {
    return 0.0; // beta -> infinity: t^beta -> 0 for t < 1
  }
  const double beta = (mean - s.minimum) / (s.maximum - mean);
  return pow(t, beta);
}

/// Ruiz et al. section 3.3: O = (1 + erf((q - mu) / sqrt(2 s2))) / 2.
VAO_HD double opennessGaussianCdf(double query, const NeighbourhoodStats& s, ErfMode erfMode)
{
  if (isFlatVariance(s.variance, s.roundingVariance))
  {
    return flatOpenness(query, s.mean, s.roundingVariance);
  }
  const double z = (query - s.mean) / sqrt(2.0 * s.variance);
  const double e = erfMode == ErfMode::Winitzki ? erfWinitzki(z) : erf(z);
  return clamp01(0.5 * (1.0 + e));
}

/// opennessChebyshev given the flat rule's rounding spread (flatRoundingSpread of the
/// rounding variance): callers that query one set of sums many times take the square root
/// once. Both answers are formed and one is kept, as the AVX2 form of the surface queries
/// (src/cpu/moment_pyramid/SurfaceLanes.h) does with masks; the bound's 0/0 on a flat box is not
/// kept.
VAO_HD double opennessChebyshevWithin(
  double query, double mean, double variance, double roundingVariance, double roundingSpread)
{
  const double d = query - mean;
  const double occluderShare = variance / (variance + d * d);
  const double bound = d > 0.0 ? clamp01(1.0 - occluderShare) : 0.0;
  return isFlatVariance(variance, roundingVariance)
    ? flatOpennessWithin(query, mean, roundingSpread)
    : bound;
}

/// Cantelli's one-tailed bound on the occluder fraction P(v >= q), as docs/methods.md section 5
/// fixes it: p_max = 1 if q <= mu, else s2 / (s2 + (q - mu)^2); O = 1 - p_max <= P(v <= q).
VAO_HD double opennessChebyshev(double query, const NeighbourhoodStats& s)
{
  return opennessChebyshevWithin(
    query, s.mean, s.variance, s.roundingVariance, flatRoundingSpread(s.roundingVariance));
}

/// Index of the first threshold >= q among the n ascending thresholds (n when none is):
/// a voxel of value v counts in channel k (v <= t_k) exactly when thresholdIndex(v) <= k.
VAO_HD int thresholdIndex(double q, const double* thresholds, int n)
{
  int lo = 0, hi = n;
  while (lo < hi)
  {
    const int mid = (lo + hi) / 2;
    if (thresholds[mid] < q)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/// Histogram CDF (docs/methods.md section 8): O = F at q, where F_k = P(v <= t_k) over the box is
/// known at the n ascending thresholds; linear between the two that enclose q, F_k itself at q =
/// t_k, 0 below t_0 and 1 at or above t_(n-1). The thresholds start at the data set's lowest value
/// and end at its highest, so both ends are exact. The box holds `count` voxels, `below` of them at
/// or under t_(upper-1) (0 for upper = 0) and `at` in (t_(upper-1), t_upper], where upper =
/// thresholdIndex(q).
VAO_HD double opennessHistogramCdfAt(
  double q, const double* thresholds, int n, int upper, double count, double below, double at)
{
  if (n <= 0 || q < thresholds[0])
  {
    return 0.0;
  }
  if (upper >= n - 1 && q >= thresholds[n - 1])
  {
    return 1.0;
  }
  const double fUpper = (below + at) / count;
  if (q == thresholds[upper])
  {
    return fUpper;
  }
  const double fLower = below / count;
  const double a = (q - thresholds[upper - 1]) / (thresholds[upper] - thresholds[upper - 1]);
  return clamp01(fLower + a * (fUpper - fLower));
}

/// Dispatch for the separable methods (the exact references count voxels instead).
VAO_HD double opennessFromStats(
  Method method, double query, const NeighbourhoodStats& s, ErfMode erfMode)
{
  switch (method)
  {
    case Method::CdfReconstruction:
      return opennessCdfReconstruction(query, s);
    case Method::Chebyshev:
      return opennessChebyshev(query, s);
    case Method::GaussianCdf:
    default:
      return opennessGaussianCdf(query, s, erfMode);
  }
}

/// count * sumSquares - sum^2 of a box's exact integer sums of v and v^2 (count^2 times
/// its variance; 0 where not positive), computed exactly (in 64 bits when it fits, as it
/// does for 16-bit data in boxes of up to 65536 voxels, else in 128) and rounded to double
/// once, so it does not depend on how the sums were formed: a distributed or streamed run
/// gives the serial bits.
VAO_HD double exactSumsNumerator(long long sum, long long sumSquares, long long count)
{
  long long a = 0, b = 0;
#if defined(__CUDA_ARCH__)
  const bool fits = false;
#else
  const bool fits =
    !__builtin_mul_overflow(count, sumSquares, &a) && !__builtin_mul_overflow(sum, sum, &b);
#endif
  if (fits)
  {
    // a - b >= 0 up to rounding-free integer arithmetic (Cauchy-Schwarz), so no overflow.
    const long long numerator = a - b;
    return numerator > 0 ? static_cast<double>(numerator) : 0.0;
  }
  const __int128 numerator =
    static_cast<__int128>(count) * sumSquares - static_cast<__int128>(sum) * sum;
  return numerator > 0 ? static_cast<double>(numerator) : 0.0;
}

/// Mean and variance of a box of `count` voxels from exact integer sums of v and v^2: the
/// variance is exactSumsNumerator / count^2.
VAO_HD void meanVarianceFromExactSums(
  long long sum, long long sumSquares, long long count, double& mean, double& variance)
{
  const double n = static_cast<double>(count);
  mean = static_cast<double>(sum) / n;
  variance = exactSumsNumerator(sum, sumSquares, count) / (n * n);
}

/// Chebyshev's bound and the Gaussian CDF (opennessFromStats) from a box's exact integer
/// sums (which have no shift and no rounding variance) without dividing out the mean and
/// the variance: with c the count, S the sum, N = exactSumsNumerator (c^2 times the
/// variance) and D = q c - S (c times q - mean), the box is flat where
/// N = 0 (exact sums: no rounding to allow for), open then where D >= -kFlatSpread |S|; else
/// Chebyshev is 1 - N / (N + D^2) where D > 0 (0 elsewhere) and the Gaussian CDF
/// (1 + erf(D / sqrt(2 N))) / 2. These are the formulas above multiplied through by c or
/// c^2: they differ from them by rounding alone (an ulp or two of a double), and cost one
/// division instead of three.
VAO_HD double opennessFromExactSums(
  Method method, double query, double count, double sum, double numerator, ErfMode erfMode)
{
  const double d = query * count - sum;
  if (numerator <= 0.0)
  {
    return d >= -(kFlatSpread * (sum < 0.0 ? -sum : sum)) ? 1.0 : 0.0;
  }
  if (method == Method::Chebyshev)
  {
    const double occluderShare = numerator / (numerator + d * d);
    return d > 0.0 ? clamp01(1.0 - occluderShare) : 0.0;
  }
  const double z = d / sqrt(2.0 * numerator);
  const double e = erfMode == ErfMode::Winitzki ? erfWinitzki(z) : erf(z);
  return clamp01(0.5 * (1.0 + e));
}

/// Mean and variance from double sums of (v - shift) and (v - shift)^2: the shift keeps
/// E[v^2] - mu^2 from cancelling catastrophically when values are large.
VAO_HD void meanVarianceFromShiftedSums(
  double sum, double sumSquares, long long count, double shift, double& mean, double& variance)
{
  const double n = static_cast<double>(count);
  const double m1 = sum / n;
  const double v = sumSquares / n - m1 * m1;
  mean = m1 + shift;
  variance = v > 0.0 ? v : 0.0;
}

/// Mean and variance from box sums of either kind: exact integer sums (no shift) or
/// double sums of values shifted by `shift`.
template <class Accumulator>
VAO_HD void meanVarianceFromSums(Accumulator sum, Accumulator sumSquares, long long count,
  double shift, double& mean, double& variance)
{
  if constexpr (std::is_integral<Accumulator>::value)
  {
    meanVarianceFromExactSums(sum, sumSquares, count, mean, variance);
  }
  else
  {
    meanVarianceFromShiftedSums(sum, sumSquares, count, shift, mean, variance);
  }
}

/// Number of voxels of a window of half-width r around i, clipped to [0, n).
VAO_HD long long clippedWindowCount(long long i, long long r, long long n)
{
  const long long lo = i - r < 0 ? 0 : i - r;
  const long long hi = i + r > n - 1 ? n - 1 : i + r;
  return hi - lo + 1;
}

} // namespace vao
