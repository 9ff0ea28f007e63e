// The validation scene of Singh et al.'s Fig. 3, generated: a floor with two boxes and
// two spheres, as an exact signed distance in voxel units of a 100^3 grid. Shared by the
// sweeping tests and the benchmark (which scales it to other grid sizes).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace vaotest
{

inline double Box(
  double x, double y, double z, double cx, double cy, double cz, double hx, double hy, double hz)
{
  const double qx = std::abs(x - cx) - hx, qy = std::abs(y - cy) - hy, qz = std::abs(z - cz) - hz;
  const double outside = std::sqrt(std::pow(std::max(qx, 0.0), 2) + std::pow(std::max(qy, 0.0), 2) +
    std::pow(std::max(qz, 0.0), 2));
  return outside + std::min(std::max({ qx, qy, qz }), 0.0);
}

inline double Sphere(double x, double y, double z, double cx, double cy, double cz, double r)
{
  return std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz)) - r;
}

/// Exact signed distance (voxel units) of the scene: a floor, two boxes, two spheres.
inline double SceneDistance(double x, double y, double z)
{
  return std::min(
    { z - 12.0, Box(x, y, z, 30, 30, 25, 10, 10, 13), Box(x, y, z, 70, 35, 22, 8, 15, 10),
      Sphere(x, y, z, 35, 70, 30, 15), Sphere(x, y, z, 70, 72, 20, 9) });
}

/// The 100^3 scene stretched over an nx x ny x nz grid as a one-voxel occupancy ramp in
/// [0, 1] (iso value 0.5; the benchmark's generated scenes), x fastest.
inline std::vector<float> SceneVolume(int nx, int ny, int nz)
{
  std::vector<float> volume(static_cast<std::size_t>(nx) * ny * nz);
  const double scale = (nx - 1) / 99.0;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
      {
        const double d =
          SceneDistance(x * 99.0 / (nx - 1), y * 99.0 / (ny - 1), z * 99.0 / (nz - 1));
        volume[(static_cast<std::size_t>(z) * ny + y) * nx + x] =
          static_cast<float>(std::min(1.0, std::max(0.0, 0.5 - d * scale)));
      }
  return volume;
}

} // namespace vaotest
