// One fuzz input through every entry point of the kernel library. The bytes choose the
// dimensions (1..40 per axis), the scalar type, the values (NaN, infinities, extremes,
// ties and plateaus included), the radii and the parameters. The properties:
// - a call succeeds, or fails with a message (never a crash, a hang, or an exception);
// - on success every openness and occlusion lies in [0, 1], and on every box that holds
//   one value only, every method gives the exact answer (q >= that value), the brute-force
//   count of docs/methods.md section 1 computed here (not for Histogram CDF, which interpolates
//   between thresholds by definition, nor for the smoothed query, which is not the box's value);
// - the box statistics are ordered: minimum <= mean <= maximum, variance >= 0.
// Used by the seeded test that runs in CI (test_fuzz_seeded.cxx) and by the libFuzzer
// target (fuzz_entry_points.cxx, `bash .ci/setup.sh fuzz`).
#pragma once

#include "vao/AmbientOcclusion.h"
#include "vao/HistogramCdf.h"
#include "vao/OcclusionSweeping.h"
#include "vao/VarianceOcclusionMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace vaofuzz
{

/// Reads the fuzz bytes as numbers; past the end it reads zeros.
class ByteReader
{
public:
  ByteReader(const std::uint8_t* data, std::size_t size)
    : Data(data)
    , Size(size)
  {
  }
  std::uint64_t bits(int bytes)
  {
    std::uint64_t value = 0;
    for (int i = 0; i < bytes; ++i)
      value = (value << 8) | (this->At < this->Size ? this->Data[this->At++] : 0u);
    return value;
  }
  int below(int n)
  {
    return n <= 1 ? 0 : static_cast<int>(this->bits(1) % static_cast<unsigned>(n));
  }
  bool flag() { return this->bits(1) & 1u; }

private:
  const std::uint8_t* Data;
  std::size_t Size;
  std::size_t At = 0;
};

/// Reports a broken property and stops (libFuzzer keeps the input).
[[noreturn]] inline void fail(const std::string& what)
{
  std::fprintf(stderr, "vao fuzz property broken: %s\n", what.c_str());
  std::abort();
}

inline void check(bool property, const std::string& what)
{
  if (!property)
    fail(what);
}

/// A value for the volume: mostly from a small palette (ties, plateaus), sometimes an
/// extreme or a non-finite one.
inline double fuzzValue(ByteReader& in, const double* palette)
{
  switch (in.below(16))
  {
    case 0:
      return std::numeric_limits<double>::quiet_NaN();
    case 1:
      return in.flag() ? std::numeric_limits<double>::infinity()
                       : -std::numeric_limits<double>::infinity();
    case 2:
      return in.flag() ? std::numeric_limits<double>::max() : std::numeric_limits<double>::lowest();
    case 3:
      return static_cast<double>(static_cast<std::int64_t>(in.bits(8))) *
        std::ldexp(1.0, in.below(200) - 100);
    default:
      return palette[in.below(4)];
  }
}

template <class T>
T toType(double v)
{
  if (std::is_floating_point<T>::value)
    return static_cast<T>(v); // NaN and infinities stay (float: large values become inf)
  if (!(v == v))
    return T(0);
  const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
  const double hi = static_cast<double>(std::numeric_limits<T>::max());
  return v <= lo ? std::numeric_limits<T>::lowest()
                 : (v >= hi ? std::numeric_limits<T>::max() : static_cast<T>(v));
}

struct FuzzVolume
{
  vao::Index3 dims;
  std::vector<double> values; // as the volume holds them, converted back to double
  std::vector<unsigned char> storage;
  vao::VolumeView view;
};

template <class T>
void fillVolume(ByteReader& in, FuzzVolume& volume, vao::ScalarType type)
{
  const std::int64_t n = volume.dims[0] * volume.dims[1] * volume.dims[2];
  const double palette[4] = { 0.0, static_cast<double>(in.bits(2)),
    -static_cast<double>(in.bits(1)), static_cast<double>(in.bits(4)) * 1e6 };
  volume.storage.resize(static_cast<std::size_t>(n) * sizeof(T));
  volume.values.resize(static_cast<std::size_t>(n));
  T* data = reinterpret_cast<T*>(volume.storage.data());
  double current = palette[0];
  for (std::int64_t i = 0; i < n; ++i)
  {
    if (in.below(8) == 0)
      current = fuzzValue(in, palette); // runs of equal values: plateaus
    data[i] = toType<T>(current);
    volume.values[i] = static_cast<double>(data[i]);
  }
  volume.view = { data, type, volume.dims, 1 };
}

inline FuzzVolume makeVolume(ByteReader& in)
{
  FuzzVolume volume;
  volume.dims = { 1 + in.below(40), 1 + in.below(40), 1 + in.below(40) };
  const auto type = static_cast<vao::ScalarType>(in.below(10));
  switch (type)
  {
    case vao::ScalarType::Int8:
      fillVolume<std::int8_t>(in, volume, type);
      break;
    case vao::ScalarType::UInt8:
      fillVolume<std::uint8_t>(in, volume, type);
      break;
    case vao::ScalarType::Int16:
      fillVolume<std::int16_t>(in, volume, type);
      break;
    case vao::ScalarType::UInt16:
      fillVolume<std::uint16_t>(in, volume, type);
      break;
    case vao::ScalarType::Int32:
      fillVolume<std::int32_t>(in, volume, type);
      break;
    case vao::ScalarType::UInt32:
      fillVolume<std::uint32_t>(in, volume, type);
      break;
    case vao::ScalarType::Int64:
      fillVolume<std::int64_t>(in, volume, type);
      break;
    case vao::ScalarType::UInt64:
      fillVolume<std::uint64_t>(in, volume, type);
      break;
    case vao::ScalarType::Float32:
      fillVolume<float>(in, volume, type);
      break;
    default:
      fillVolume<double>(in, volume, vao::ScalarType::Float64);
      break;
  }
  return volume;
}

/// The value of voxel (x, y, z) when its clipped box holds one value only; NaN otherwise.
inline double flatValue(
  const FuzzVolume& v, std::int64_t x, std::int64_t y, std::int64_t z, const vao::Radius& r)
{
  const vao::Index3& d = v.dims;
  const double first = v.values[(z * d[1] + y) * d[0] + x];
  for (std::int64_t k = std::max<std::int64_t>(0, z - r.z); k <= std::min(d[2] - 1, z + r.z); ++k)
    for (std::int64_t j = std::max<std::int64_t>(0, y - r.y); j <= std::min(d[1] - 1, y + r.y); ++j)
      for (std::int64_t i = std::max<std::int64_t>(0, x - r.x); i <= std::min(d[0] - 1, x + r.x);
           ++i)
        if (!(v.values[(k * d[1] + j) * d[0] + i] == first))
          return std::numeric_limits<double>::quiet_NaN();
  return first;
}

inline void fuzzAmbientOcclusion(ByteReader& in, const FuzzVolume& v)
{
  vao::AmbientOcclusionParameters p;
  p.method = static_cast<vao::Method>(in.below(6));
  p.radius = { in.below(7), in.below(7), in.below(7) };
  p.erfMode = in.flag() ? vao::ErfMode::Winitzki : vao::ErfMode::Exact;
  const int query = in.below(5);
  p.queryMode = query == 0
    ? vao::QueryMode::IsoValue
    : (query == 1 ? vao::QueryMode::SmoothedValue : vao::QueryMode::VoxelValue);
  p.isoValue =
    in.below(8) == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(in.bits(1));
  p.querySmoothing = in.below(24) / 8.0; // 0 (refused) to 2.875 voxels
  if (p.method == vao::Method::HistogramCdf &&
    !vao::volumeThresholds(v.view, 2 + in.below(300), p.thresholds).ok)
    p.thresholds = { static_cast<double>(in.bits(1)),
      static_cast<double>(in.bits(1)) }; // maybe not ascending
  const std::size_t n = v.values.size();
  const std::int64_t box = (2 * p.radius.x + 1) * (2 * p.radius.y + 1) * (2 * p.radius.z + 1);
  const bool exact = p.method == vao::Method::ExactBox || p.method == vao::Method::ExactSphere;
  if (exact && static_cast<std::int64_t>(n) * box > 20000000)
    p.method = vao::Method::GaussianCdf; // the O(R^3) references: small cases only (speed)
  std::vector<float> open(n, -1.0f), variance(n, -1.0f);
  const vao::Status s = vao::computeAmbientOcclusion(
    v.view, vao::Region::whole(v.view), p, { open.data(), in.flag() ? variance.data() : nullptr });
  if (!s.ok)
  {
    check(!s.message.empty(), "a failed Volumetric AO call says why");
    return;
  }
  if (p.queryMode == vao::QueryMode::SmoothedValue || p.method == vao::Method::HistogramCdf)
  {
    // No flat rule here: the smoothed query is not the box's value, and Histogram CDF
    // interpolates between thresholds by definition (docs/methods.md section 8).
    for (std::size_t i = 0; i < n; ++i)
      check(open[i] >= 0.0f && open[i] <= 1.0f, "openness in [0, 1] at voxel " + std::to_string(i));
    return;
  }
  const vao::Index3& d = v.dims;
  double largest = 0.0;
  for (double value : v.values)
    largest = std::isfinite(value) ? std::max(largest, std::abs(value)) : largest;
  // The brute-force flat test on at most ~4e6 box voxels: every step-th voxel.
  const std::int64_t step = std::max<std::int64_t>(1, static_cast<std::int64_t>(n) * box / 4000000);
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i)
    check(open[i] >= 0.0f && open[i] <= 1.0f, "openness in [0, 1] at voxel " + std::to_string(i));
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); i += step)
  {
    const std::int64_t x = i % d[0], y = (i / d[0]) % d[1], z = i / (d[0] * d[1]);
    const double flat = flatValue(v, x, y, z, p.radius);
    const double q = p.queryMode == vao::QueryMode::IsoValue ? p.isoValue : flat;
    // A flat box: the exact openness is q >= its value. An iso value within the
    // rounding of double sums of the flat value is a precision limit (Estimators.h,
    // flatOpenness): 1e-9 of the data's largest magnitude covers it.
    if (flat == flat && (q == flat || std::abs(q - flat) > 1e-9 * (largest + 1.0)))
    {
      check(open[i] == (q >= flat ? 1.0f : 0.0f),
        "method " + std::to_string(static_cast<int>(p.method)) +
          ": exact on the flat box of voxel " + std::to_string(i) + " (value " +
          std::to_string(flat) + ", got " + std::to_string(open[i]) + ")");
    }
  }
}

inline void fuzzBoxStatistics(ByteReader& in, const FuzzVolume& v)
{
  const vao::Radius r{ in.below(6), in.below(6), in.below(6) };
  const std::size_t n = v.values.size();
  std::vector<double> mean(n), variance(n), minimum(n), maximum(n);
  const vao::Status s = vao::computeBoxStatistics(v.view, vao::Region::whole(v.view), r,
    { nullptr, mean.data(), variance.data(), minimum.data(), maximum.data() });
  check(s.ok, "box statistics of a valid volume: " + s.message);
  // The double sums round with the data's largest magnitude, not the box's.
  double largest = 0.0;
  for (double value : v.values)
    largest = std::isfinite(value) ? std::max(largest, std::abs(value)) : largest;
  const double slack = 1e-9 * (largest + 1.0);
  for (std::size_t i = 0; i < n; ++i)
  {
    const double range = maximum[i] - minimum[i];
    if (!std::isfinite(range) || !std::isfinite(mean[i]))
      continue; // non-finite data: no order to check
    check(minimum[i] <= maximum[i], "min <= max");
    check(mean[i] >= minimum[i] - slack && mean[i] <= maximum[i] + slack, "min <= mean <= max");
    check(variance[i] >= 0.0, "variance >= 0");
  }
}

inline void fuzzSweeping(ByteReader& in, const FuzzVolume& v)
{
  vao::SweepParameters p;
  p.isoValue = static_cast<double>(in.bits(1)) - 64.0;
  p.insideIsAbove = in.flag();
  p.iterations = 1 + in.below(3);
  p.useGeometryTerm = in.flag();
  p.opacity = in.below(4) / 3.0;
  const std::array<double, 3> spacing = { std::ldexp(1.0 + in.below(4), in.below(80) - 40), 1.0,
    0.5 + in.below(3) };
  const std::size_t n = v.values.size();
  std::vector<float> d(n), a(n);
  const vao::Status s = vao::computeOcclusionSweeping(v.view, spacing, p, { d.data(), a.data() });
  if (!s.ok)
  {
    check(!s.message.empty(), "a failed sweep says why");
    return;
  }
  for (std::size_t i = 0; i < n; ++i)
  {
    check(!(d[i] != d[i]), "no NaN distance");
    check(a[i] >= 0.0f && a[i] <= 1.0f, "sweeping AO in [0, 1]");
  }
}

inline void fuzzPyramid(ByteReader& in, const FuzzVolume& v)
{
  vao::PyramidParameters pp;
  pp.levels = 1 + in.below(4);
  pp.startAtHalfResolution = in.flag();
  std::vector<vao::MomentLevel> pyramid;
  const vao::Status s = vao::buildMomentPyramid(v.view, { 0, 0, 0 }, { 1, 1, 1 }, pp, pyramid);
  if (!s.ok)
  {
    check(!s.message.empty() && pyramid.empty(), "a failed pyramid says why and is empty");
    return;
  }
  std::vector<double> points, normals;
  for (int i = 0; i < 16; ++i)
  {
    for (int a = 0; a < 3; ++a)
      points.push_back(static_cast<double>(in.below(48)) - 4.0);
    normals.push_back(1.0 + in.below(3));
    normals.push_back(static_cast<double>(in.below(3)) - 1.0);
    normals.push_back(0.5);
  }
  vao::SurfaceOcclusionParameters sp;
  sp.estimator = in.flag() ? vao::Method::GaussianCdf : vao::Method::Chebyshev;
  std::vector<float> ao(16, -1.0f), shadow(16, -1.0f);
  const vao::Status a = vao::surfaceAmbientOcclusion(
    pyramid, v.view, { 0, 0, 0 }, { 1, 1, 1 }, points.data(), normals.data(), 16, sp, ao.data());
  const vao::Status b = vao::surfaceShadow(
    pyramid, points.data(), normals.data(), 16, { 0.2, -1.0, 0.3 }, sp, shadow.data());
  check(a.ok && b.ok, "surface queries of a valid pyramid: " + a.message + b.message);
  for (int i = 0; i < 16; ++i)
    check(ao[i] >= 0.0f && ao[i] <= 1.0f && shadow[i] >= 0.0f && shadow[i] <= 1.0f,
      "surface AO and shadow in [0, 1]");
}

/// One fuzz input through every entry point.
inline void fuzzOnce(const std::uint8_t* data, std::size_t size)
{
  ByteReader in(data, size);
  const FuzzVolume volume = makeVolume(in);
  fuzzAmbientOcclusion(in, volume);
  fuzzBoxStatistics(in, volume);
  fuzzSweeping(in, volume);
  fuzzPyramid(in, volume);
}

} // namespace vaofuzz
