// Random test volumes and brute-force references, independent of the library's code paths.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <type_traits>
#include <vector>

namespace vaotest
{

/// A moment method with its erf: the cases every path of the separable methods is tested on.
struct MethodCase
{
  vao::Method method;
  vao::ErfMode erf;
  const char* name;
};

inline const MethodCase kSeparableMethods[] = {
  { vao::Method::CdfReconstruction, vao::ErfMode::Exact, "CDF Reconstruction" },
  { vao::Method::GaussianCdf, vao::ErfMode::Exact, "Gaussian CDF" },
  { vao::Method::GaussianCdf, vao::ErfMode::Winitzki, "Gaussian CDF (Winitzki)" },
  { vao::Method::Chebyshev, vao::ErfMode::Exact, "Chebyshev" },
};

/// The separable methods and their oracle.
inline const MethodCase kMomentMethodsAndExactBox[] = {
  kSeparableMethods[0],
  kSeparableMethods[1],
  kSeparableMethods[2],
  kSeparableMethods[3],
  { vao::Method::ExactBox, vao::ErfMode::Exact, "Exact Box" },
};

template <class T>
vao::ScalarType scalarTypeOf();
template <>
inline vao::ScalarType scalarTypeOf<std::int8_t>()
{
  return vao::ScalarType::Int8;
}
template <>
inline vao::ScalarType scalarTypeOf<std::uint8_t>()
{
  return vao::ScalarType::UInt8;
}
template <>
inline vao::ScalarType scalarTypeOf<std::int16_t>()
{
  return vao::ScalarType::Int16;
}
template <>
inline vao::ScalarType scalarTypeOf<std::uint16_t>()
{
  return vao::ScalarType::UInt16;
}
template <>
inline vao::ScalarType scalarTypeOf<std::int32_t>()
{
  return vao::ScalarType::Int32;
}
template <>
inline vao::ScalarType scalarTypeOf<std::uint32_t>()
{
  return vao::ScalarType::UInt32;
}
template <>
inline vao::ScalarType scalarTypeOf<std::int64_t>()
{
  return vao::ScalarType::Int64;
}
template <>
inline vao::ScalarType scalarTypeOf<std::uint64_t>()
{
  return vao::ScalarType::UInt64;
}
template <>
inline vao::ScalarType scalarTypeOf<float>()
{
  return vao::ScalarType::Float32;
}
template <>
inline vao::ScalarType scalarTypeOf<double>()
{
  return vao::ScalarType::Float64;
}

/// Values drawn uniformly from [lo, hi] (integers) with a few repeated plateaus, so that
/// flat and two-valued neighbourhoods occur too.
template <class T>
std::vector<T> randomVolume(const vao::Index3& dims, double lo, double hi, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(lo, hi);
  const std::int64_t n = dims[0] * dims[1] * dims[2];
  std::vector<T> v(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i)
  {
    const double value = uniform(rng);
    v[i] = static_cast<T>(std::is_integral<T>::value ? std::floor(value) : value);
  }
  // A constant block in one corner.
  for (std::int64_t z = 0; z < std::min<std::int64_t>(4, dims[2]); ++z)
    for (std::int64_t y = 0; y < std::min<std::int64_t>(4, dims[1]); ++y)
      for (std::int64_t x = 0; x < std::min<std::int64_t>(4, dims[0]); ++x)
        v[(z * dims[1] + y) * dims[0] + x] = static_cast<T>(lo);
  return v;
}

template <class T>
vao::VolumeView viewOf(const std::vector<T>& data, const vao::Index3& dims, std::int64_t stride = 1)
{
  vao::VolumeView view;
  view.data = data.data();
  view.type = scalarTypeOf<T>();
  view.dims = dims;
  view.voxelStride = stride;
  return view;
}

struct ReferenceStats
{
  double count, mean, variance, minimum, maximum;
};

/// Two-pass brute force over the clipped box, in double (long double for the variance).
template <class T>
ReferenceStats bruteForceStats(const std::vector<T>& v, const vao::Index3& d, const vao::Radius& r,
  std::int64_t x, std::int64_t y, std::int64_t z)
{
  ReferenceStats s{ 0, 0, 0, 0, 0 };
  long double sum = 0;
  bool first = true;
  auto forEach = [&](auto&& f)
  {
    for (std::int64_t k = std::max<std::int64_t>(0, z - r.z); k <= std::min(d[2] - 1, z + r.z); ++k)
      for (std::int64_t j = std::max<std::int64_t>(0, y - r.y); j <= std::min(d[1] - 1, y + r.y);
           ++j)
        for (std::int64_t i = std::max<std::int64_t>(0, x - r.x); i <= std::min(d[0] - 1, x + r.x);
             ++i)
          f(static_cast<long double>(v[(k * d[1] + j) * d[0] + i]));
  };
  forEach(
    [&](long double value)
    {
      sum += value;
      s.count += 1;
      if (first || value < s.minimum)
        s.minimum = static_cast<double>(value);
      if (first || value > s.maximum)
        s.maximum = static_cast<double>(value);
      first = false;
    });
  const long double mean = sum / s.count;
  long double m2 = 0;
  forEach([&](long double value) { m2 += (value - mean) * (value - mean); });
  s.mean = static_cast<double>(mean);
  s.variance = static_cast<double>(m2 / s.count);
  return s;
}

/// Brute-force fraction of the clipped box (or ellipsoid) with values <= q.
template <class T>
double bruteForceOpenness(const std::vector<T>& v, const vao::Index3& d, const vao::Radius& r,
  std::int64_t x, std::int64_t y, std::int64_t z, double q, bool sphere)
{
  double below = 0, total = 0;
  for (std::int64_t dz = -r.z; dz <= r.z; ++dz)
    for (std::int64_t dy = -r.y; dy <= r.y; ++dy)
      for (std::int64_t dx = -r.x; dx <= r.x; ++dx)
      {
        const std::int64_t i = x + dx, j = y + dy, k = z + dz;
        if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2])
          continue;
        if (sphere)
        {
          auto term = [](std::int64_t delta, int radius)
          {
            return radius == 0 ? (delta == 0 ? 0.0 : 2.0)
                               : double(delta) * delta / (double(radius) * radius);
          };
          if (term(dx, r.x) + term(dy, r.y) + term(dz, r.z) > 1.0 + 1e-12)
            continue;
        }
        total += 1;
        below += static_cast<double>(v[(k * d[1] + j) * d[0] + i]) <= q ? 1 : 0;
      }
  return below / total;
}

} // namespace vaotest
