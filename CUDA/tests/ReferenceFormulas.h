// The estimators of docs/methods.md written out again for the tests, from the text, not from
// Estimators.h: a reference that called the library's own formulas would share its bugs.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace vaotest
{
namespace reference
{

struct Statistics
{
  double mean, variance, minimum, maximum;
  double roundingVariance = 0.0; // what rounded sums can give a flat box (0: exact sums)
};

/// docs/methods.md (Notation, flat boxes): flat when s2 is at most the sums' rounding
/// variance, or vmax == vmin; then O = (q >= mu). No threshold relative to mu^2 or 1: that
/// would make data stored with a large offset or in small units flat everywhere.
inline bool flat(const Statistics& s)
{
  return s.maximum == s.minimum || s.variance <= s.roundingVariance;
}

inline double flatAnswer(double q, const Statistics& s)
{
  return q >= s.mean ? 1.0 : 0.0;
}

/// Ruiz et al. 3.2: t = (q - vmin) / (vmax - vmin) in [0, 1], beta = (mu - vmin) / (vmax - mu),
/// O = t^beta, 1 when t >= 1.
inline double cdfReconstruction(double q, const Statistics& s)
{
  if (s.maximum == s.minimum)
    return q >= s.minimum ? 1.0 : 0.0;
  const double t = std::fmin(1.0, std::fmax(0.0, (q - s.minimum) / (s.maximum - s.minimum)));
  if (t >= 1.0)
    return 1.0;
  const double mu = std::fmin(s.maximum, std::fmax(s.minimum, s.mean));
  if (mu >= s.maximum)
    return 0.0; // beta infinite
  return std::pow(t, (mu - s.minimum) / (s.maximum - mu));
}

/// Winitzki: erf(x) ~ sign(x) sqrt(1 - exp(-x^2 (4/pi + a x^2) / (1 + a x^2))),
/// a = 8(pi - 3) / (3 pi (4 - pi)).
inline double winitzki(double x)
{
  const double pi = std::acos(-1.0);
  const double a = 8.0 * (pi - 3.0) / (3.0 * pi * (4.0 - pi));
  const double value =
    std::sqrt(std::fmax(0.0, 1.0 - std::exp(-x * x * (4.0 / pi + a * x * x) / (1.0 + a * x * x))));
  return x < 0 ? -value : value;
}

/// Ruiz et al. 3.3: O = (1 + erf((q - mu) / sqrt(2 s2))) / 2.
inline double gaussianCdf(double q, const Statistics& s, bool useWinitzki)
{
  if (flat(s))
    return flatAnswer(q, s);
  const double x = (q - s.mean) / std::sqrt(2.0 * s.variance);
  return 0.5 * (1.0 + (useWinitzki ? winitzki(x) : std::erf(x)));
}

/// Cantelli: p_max = 1 if q <= mu, else s2 / (s2 + (q - mu)^2); O = 1 - p_max.
inline double chebyshev(double q, const Statistics& s)
{
  if (flat(s))
    return flatAnswer(q, s);
  if (q <= s.mean)
    return 0.0;
  return 1.0 - s.variance / (s.variance + (q - s.mean) * (q - s.mean));
}

/// docs/methods.md section 8, Histogram CDF: with F(t) = P(v <= t) over the box, O = 0 when q is
/// below the lowest threshold, 1 at or above the highest, F(t_k) at q = t_k, and between the two
/// enclosing thresholds the straight line through (t_k, F(t_k)) and (t_k+1, F(t_k+1)).
template <class Fraction>
double histogramCdf(double q, const std::vector<double>& t, Fraction&& fractionAtOrBelow)
{
  if (t.empty() || q < t.front())
    return 0.0;
  if (q >= t.back())
    return 1.0;
  size_t k = 0;
  while (!(t[k] <= q && q < t[k + 1]))
    ++k;
  const double f0 = fractionAtOrBelow(t[k]);
  if (q == t[k])
    return f0;
  const double f1 = fractionAtOrBelow(t[k + 1]);
  return f0 + (q - t[k]) / (t[k + 1] - t[k]) * (f1 - f0);
}

/// docs/methods.md (Notation): the trilinear value at world point p of a grid of dims[a]
/// values get(i, j, k) on each axis, the first at `origin`, `spacing` apart; p is clamped to
/// the grid. The sum over the cell's 8 corners of the product of the per-axis weights.
template <class Dims, class Point, class Get>
double trilinear(
  const Dims& dims, const Point& origin, const Point& spacing, const Point& p, Get get)
{
  long long lo[3], hi[3];
  double w[3];
  for (int a = 0; a < 3; ++a)
  {
    const double last = static_cast<double>(dims[a] - 1);
    const double u = std::fmin(std::fmax((p[a] - origin[a]) / spacing[a], 0.0), last);
    lo[a] = static_cast<long long>(std::floor(u));
    hi[a] = std::min<long long>(lo[a] + 1, static_cast<long long>(dims[a] - 1));
    w[a] = u - std::floor(u);
  }
  double sum = 0.0;
  for (int c = 0; c < 8; ++c)
  {
    double weight = 1.0;
    long long i[3];
    for (int a = 0; a < 3; ++a)
    {
      const bool upper = (c >> a) & 1;
      i[a] = upper ? hi[a] : lo[a];
      weight *= upper ? w[a] : 1.0 - w[a];
    }
    sum += weight * get(i[0], i[1], i[2]);
  }
  return sum;
}

} // namespace reference
} // namespace vaotest
