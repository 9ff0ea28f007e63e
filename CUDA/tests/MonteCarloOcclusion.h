// Monte-Carlo ambient occlusion, the reference that the sweeping (test_sweeping_validation)
// and the pyramid (Testing/Cxx/TestIsosurfaceAmbientOcclusion) are held to, and the
// statistics they compare with it. The caller traces each ray through its own scene; the
// sampling is shared, so that a seed gives the same rays in every test that uses it (their
// thresholds were measured with those rays).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace vaotest
{

/// Fraction of `rays` cosine-weighted directions about the unit outward normal n for which
/// `blocked(d)` is false: the ambient occlusion of Eq. 2 / pi, as openness. `blocked`
/// gets each unit direction d (const double[3]) and says whether the ray along it from the
/// caller's point meets the scene. Two uniforms per ray, drawn from `rng` in a fixed order.
template <class Blocked>
double MonteCarloAO(const double n[3], int rays, std::mt19937& rng, Blocked&& blocked)
{
  // An orthonormal frame (t, b, n).
  const double helper[3] = { std::abs(n[0]) < 0.9 ? 1.0 : 0.0, std::abs(n[0]) < 0.9 ? 0.0 : 1.0,
    0.0 };
  double t[3] = { n[1] * helper[2] - n[2] * helper[1], n[2] * helper[0] - n[0] * helper[2],
    n[0] * helper[1] - n[1] * helper[0] };
  const double tl = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  for (double& c : t)
    c /= tl;
  const double b[3] = { n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2],
    n[0] * t[1] - n[1] * t[0] };
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int open = 0;
  for (int ray = 0; ray < rays; ++ray)
  {
    // Cosine-weighted: uniform on the disk, lifted to the hemisphere.
    const double u1 = uniform(rng), u2 = uniform(rng);
    const double r = std::sqrt(u1), phi = 2 * M_PI * u2;
    const double a = r * std::cos(phi), c = r * std::sin(phi), h = std::sqrt(std::max(0.0, 1 - u1));
    const double d[3] = { a * t[0] + c * b[0] + h * n[0], a * t[1] + c * b[1] + h * n[1],
      a * t[2] + c * b[2] + h * n[2] };
    open += blocked(d) ? 0 : 1;
  }
  return static_cast<double>(open) / rays;
}

struct Agreement
{
  double meanEstimate, meanReference, correlation; // correlation: Pearson's
};

/// How an estimate follows the reference at the same points (two vectors of one length).
inline Agreement AgreementOf(
  const std::vector<double>& estimate, const std::vector<double>& reference)
{
  const double n = static_cast<double>(estimate.size());
  double me = 0, mr = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i)
  {
    me += estimate[i];
    mr += reference[i];
  }
  me /= n;
  mr /= n;
  double ser = 0, see = 0, srr = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i)
  {
    ser += (estimate[i] - me) * (reference[i] - mr);
    see += (estimate[i] - me) * (estimate[i] - me);
    srr += (reference[i] - mr) * (reference[i] - mr);
  }
  return { me, mr, ser / std::sqrt(see * srr) };
}

} // namespace vaotest
