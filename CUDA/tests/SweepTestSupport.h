// Helpers of the occlusion sweeping tests: scenes given by a signed distance function,
// running the whole-volume kernel, and comparing results.
#pragma once

#include "TestVolumes.h"
#include "vao/OcclusionSweeping.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

namespace vaotest
{

using Spacing = std::array<double, 3>;
using Sdf = std::function<double(double, double, double)>;

// ---------------------------------------------------------------------------------------
// Scenes: v = -(exact signed distance), so inside (v > 0) is the occluder at iso value 0.

struct Scene
{
  vao::Index3 dims;
  Spacing spacing;
  std::vector<float> values;
  std::vector<double> exact; // signed distance, world units

  vao::VolumeView view() const { return viewOf(this->values, this->dims); }
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    return (z * this->dims[1] + y) * this->dims[0] + x;
  }
};

inline Scene makeScene(const vao::Index3& dims, const Spacing& h, const Sdf& sdf)
{
  Scene scene{ dims, h, {}, {} };
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
      {
        const double d = sdf(x * h[0], y * h[1], z * h[2]);
        scene.exact.push_back(d);
        scene.values.push_back(static_cast<float>(-d));
      }
  return scene;
}

inline Sdf sphere(double cx, double cy, double cz, double r)
{
  return [=](double x, double y, double z)
  { return std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz)) - r; };
}

inline Sdf box(double cx, double cy, double cz, double hx, double hy, double hz)
{
  return [=](double x, double y, double z)
  {
    const double qx = std::abs(x - cx) - hx, qy = std::abs(y - cy) - hy, qz = std::abs(z - cz) - hz;
    const double ox = std::max(qx, 0.0), oy = std::max(qy, 0.0), oz = std::max(qz, 0.0);
    return std::sqrt(ox * ox + oy * oy + oz * oz) + std::min(std::max({ qx, qy, qz }), 0.0);
  };
}

inline Sdf torus(double cx, double cy, double cz, double major, double minor)
{
  return [=](double x, double y, double z)
  {
    const double q = std::hypot(x - cx, y - cy) - major;
    return std::hypot(q, z - cz) - minor;
  };
}

/// Occluders for the visibility tests (not exact distances: only the iso surface matters).
inline Sdf spheresAndBox()
{
  const Sdf a = sphere(9.3, 10.2, 8.1, 5.5), b = sphere(20.4, 14.1, 13.2, 4.2),
            c = box(14.2, 6.3, 4.1, 9.0, 3.1, 2.2);
  return [=](double x, double y, double z) {
    return std::min({ a(x, y, z), b(x, y, z), c(x, y, z) });
  };
}

// ---------------------------------------------------------------------------------------
// Running the kernel

struct Result
{
  vao::Status status;
  vao::SweepReport report;
  std::vector<float> distance, occlusion, octants;

  float octant(std::int64_t i, int s) const { return this->octants[8 * i + s]; }
};

inline Result sweep(const vao::VolumeView& view, const Spacing& h, const vao::SweepParameters& p,
  int threads = 0, bool withOctants = true)
{
  const std::int64_t n = view.voxelCount();
  Result r;
  r.distance.assign(n, -7.0f);
  r.occlusion.assign(n, -7.0f);
  if (withOctants)
    r.octants.assign(8 * n, -7.0f);
  vao::Execution execution;
  execution.threads = threads;
  r.status = vao::computeOcclusionSweeping(view, h, p,
    { r.distance.data(), r.occlusion.data(), withOctants ? r.octants.data() : nullptr }, execution,
    &r.report);
  return r;
}

inline vao::SweepParameters withIterations(int iterations, double tolerance = 0.0)
{
  vao::SweepParameters p;
  p.iterations = iterations;
  p.tolerance = tolerance;
  return p;
}

/// Iterated until a pass changes nothing: then every V was computed with the final D.
inline vao::SweepParameters converged()
{
  return withIterations(50, 1e-30);
}

struct Errors
{
  double max = 0, maxOutside = 0, mean = 0;
};

inline Errors distanceErrors(const Scene& scene, const std::vector<float>& distance)
{
  Errors e;
  for (std::size_t i = 0; i < distance.size(); ++i)
  {
    const double error = std::abs(distance[i] - scene.exact[i]);
    e.max = std::max(e.max, error);
    if (scene.exact[i] > 0)
      e.maxOutside = std::max(e.maxOutside, error);
    e.mean += error / distance.size();
  }
  return e;
}

/// Largest |a - b|, relative to max(1, |b|) when `relative`.
inline double largestDifference(
  const std::vector<float>& a, const std::vector<float>& b, bool relative = false)
{
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst,
      std::abs(double(a[i]) - b[i]) / (relative ? std::max(1.0, std::abs(double(b[i]))) : 1.0));
  return worst;
}

} // namespace vaotest
