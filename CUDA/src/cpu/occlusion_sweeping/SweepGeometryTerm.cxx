// The geometry term G_s(N) of occlusion sweeping (Singh et al. Eq. 5) in closed form, and
// the octant numbering shared by the sweeps.
#include "cpu/occlusion_sweeping/SweepingCore.h"

#include <cmath>

namespace vao
{
namespace detail
{
namespace sweeping
{
namespace
{

constexpr double kPi = 3.14159265358979323846;

/// atan2(y, x) for x, y >= 0, to ~1e-10 and cheaper than std::atan2 (the geometry term
/// needs six of them per voxel). The ratio is reduced to |t| <= tan(pi/8)
/// with atan(r) = pi/4 + atan((r - 1) / (r + 1)), where the odd series converges fast.
double quadrantAngle(double y, double x)
{
  constexpr double kTanPiOver8 = 0.41421356237309503;
  const bool steep = y > x;
  const double lo = steep ? x : y, hi = steep ? y : x;
  if (!(hi > 0.0))
  {
    return 0.0;
  }
  double t = lo / hi;
  double base = 0.0;
  if (t > kTanPiOver8)
  {
    t = (lo - hi) / (lo + hi);
    base = 0.25 * kPi;
  }
  // Terms up to t^21: the first omitted one is below 0.4143^23 / 23 < 1e-10.
  static constexpr double kSeries[11] = { 1.0, -1.0 / 3, 1.0 / 5, -1.0 / 7, 1.0 / 9, -1.0 / 11,
    1.0 / 13, -1.0 / 15, 1.0 / 17, -1.0 / 19, 1.0 / 21 };
  const double t2 = t * t;
  double series = kSeries[10];
  for (int k = 9; k >= 0; --k)
  {
    series = series * t2 + kSeries[k];
  }
  const double angle = base + t * series;
  return steep ? 0.5 * kPi - angle : angle;
}

} // namespace

std::array<double, 3> unitNormal(double x, double y, double z)
{
  const double length = std::sqrt(x * x + y * y + z * z);
  if (!(length > 0.0) || !std::isfinite(length))
  {
    return { 0.0, 0.0, 1.0 };
  }
  return { x / length, y / length, z / length };
}

/// G_s(N) of all eight octants for a unit N (twoSided: G_s(N) + G_s(-N)).
///
/// Octant s is {w : sign(w) = -sweepDirection(s)}; flipping those signs maps it to the
/// positive octant, so G_s(N) = F(M) with M_i = -dir_i N_i and
/// F(M) = integral over the positive octant of max(M.w, 0) dw. F depends on |N_i| = p_i
/// and on the set of negative components of M:
/// - none: the whole octant is lit, F = M . Phi with the octant's vector irradiance
///   Phi = (pi/4)(1, 1, 1);
/// - only M_k: the octant clipped by M.w = 0 is the quadrilateral x_i, x_j, p_jk, p_ki;
///   Lambert's formula (1/2) sum_e theta_e (M . n_e) over its edges (normals x_k, x_i,
///   x_j, and M itself on the cut, whose arc is atan2(p_k, p_i p_j) for a unit M) gives
///   F = (1/2)(-(pi/2) p_k + p_i atan2(p_j, p_k) + p_j atan2(p_i, p_k) + atan2(p_k, p_i p_j));
/// - all but M_k: F(M) = F(-M) + M . Phi, because max(t, 0) - max(-t, 0) = t;
/// - all: 0.
/// The eight values of F are tabulated by that set (bit i: M_i < 0), so that each octant
/// is a lookup.
void allGeometryTerms(const std::array<double, 3>& n, bool twoSided, double g[8])
{
  const double p[3] = { std::abs(n[0]), std::abs(n[1]), std::abs(n[2]) };
  double angle[3][3] = {}; // angle[i][k] = atan2(p_i, p_k); the pair sums to pi/2
  for (int i = 0; i < 3; ++i)
    for (int k = i + 1; k < 3; ++k)
    {
      angle[i][k] = quadrantAngle(p[i], p[k]);
      angle[k][i] = 0.5 * kPi - angle[i][k];
    }
  double irradiance[8]; // M . Phi by the set of negative components
  for (int m = 0; m < 8; ++m)
  {
    irradiance[m] =
      0.25 * kPi * (((m & 1) ? -p[0] : p[0]) + ((m & 2) ? -p[1] : p[1]) + ((m & 4) ? -p[2] : p[2]));
  }
  double f[8];
  f[0] = irradiance[0];
  f[7] = 0.0;
  for (int k = 0; k < 3; ++k)
  {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const int only = 1 << k, allBut = 7 ^ only;
    f[only] = 0.5 *
      (-0.5 * kPi * p[k] + p[i] * angle[j][k] + p[j] * angle[i][k] +
        quadrantAngle(p[k], p[i] * p[j]));
    f[allBut] = irradiance[allBut] + f[only];
  }
  // M_i = -dir_i N_i < 0: N_i > 0 on a + axis of the sweep (bit i of s clear), N_i < 0 on a - axis.
  const int positive = (n[0] > 0) | (n[1] > 0) << 1 | (n[2] > 0) << 2;
  const int negative = (n[0] < 0) | (n[1] < 0) << 1 | (n[2] < 0) << 2;
  for (int s = 0; s < 8; ++s)
  {
    const int m = ((~s & positive) | (s & negative)) & 7;
    g[s] = twoSided ? 2.0 * f[m] - irradiance[m] : f[m]; // F(-M) = F(M) - M . Phi
  }
}

} // namespace sweeping
} // namespace detail
} // namespace vao

std::array<int, 3> vao::sweepDirection(int octant)
{
  return { (octant & 1) ? -1 : 1, (octant & 2) ? -1 : 1, (octant & 4) ? -1 : 1 };
}

double vao::geometryTerm(int octant, const std::array<double, 3>& normal, bool twoSided)
{
  if (octant < 0 || octant > 7)
  {
    return 0.0;
  }
  double g[8];
  detail::sweeping::allGeometryTerms(
    detail::sweeping::unitNormal(normal[0], normal[1], normal[2]), twoSided, g);
  return g[octant];
}
