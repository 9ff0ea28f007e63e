// Rays: Exact Rays' AO estimated from 26 cones around the lattice directions, each cone's
// transmittance from a near part (the first lattice step, sampled finely and classified
// after interpolation, as the rays are) and a far part (lattice points of box-blurred cell
// means of the extinction, the blur widening with the distance as the cone does).
//
// Along a lattice direction every sample lies at the same offset from every voxel, so a
// result reads fixed neighbours; the far samples thin out geometrically, which makes the
// cost grow like log R. The constants (near spacing, cone width, far gamma) were chosen
// against Exact Rays on real scans (docs/methods.md section 12, docs/accuracy.md).
#include "cpu/ray_casting/RayEstimate.h"

#include "VolumeAccess.h"
#include "cpu/common/ConcurrentRange.h"
#include "cpu/common/Parallel.h"
#include "cpu/ray_casting/ExactRays.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numeric>

namespace vao
{
namespace detail
{
namespace
{

/// Near samples lie at most this many smallest spacings apart.
constexpr double kNearSpacing = 0.6;
/// A far sample at distance r reads a blur of side kConeWidth r (at least one spacing).
constexpr double kConeWidth = 0.6;
/// The far part transmits (1 + tau / K)^-K: between exp(-tau) of a thin ray and the
/// brighter mean of exp(-tau) over a cone whose optical depth varies.
constexpr double kFarGamma = 4.0;
/// The blur levels' sides in smallest spacings (level 0: the cell means themselves).
constexpr double kLevelSides[] = { 1.0, 1.5, 2.0, 3.0, 4.0, 6.0 };
constexpr int kLevels = sizeof(kLevelSides) / sizeof(kLevelSides[0]);
/// The sphere's share of a cone: the fraction of this many Fibonacci directions nearest it.
constexpr int kWeightDirections = 20000;
/// Extinction tabulated over the opacity function's points: cells per table.
constexpr int kTableCells = 4096;

/// The far samples' lattice steps: 1, 2, 3, 4, 6, 8, 11, 16, then about sqrt 2 apart.
std::vector<int> farSteps(int last)
{
  std::vector<int> steps;
  for (int k : { 1, 2, 3, 4, 6, 8, 11, 16 })
    if (k <= last)
      steps.push_back(k);
  for (double k = 16.0 * std::sqrt(2.0); static_cast<int>(std::lround(k)) <= last;
       k *= std::sqrt(2.0))
    steps.push_back(static_cast<int>(std::lround(k)));
  if (steps.empty() || steps.back() < last)
    steps.push_back(last);
  return steps;
}

/// The box kernel of side w voxels over cell-constant values: the weight of the cell at
/// offset o is its overlap with [-w/2, w/2], over w. Empty for w <= 1 (no blur).
std::vector<double> boxKernel(double w)
{
  if (!(w > 1.0 + 1e-9))
    return {};
  const int half = static_cast<int>(std::ceil(w / 2.0 - 0.5 - 1e-9));
  std::vector<double> kernel(static_cast<std::size_t>(2 * half + 1));
  for (int o = -half; o <= half; ++o)
  {
    const double overlap = std::min(o + 0.5, w / 2.0) - std::max(o - 0.5, -w / 2.0);
    kernel[static_cast<std::size_t>(o + half)] = std::max(0.0, overlap) / w;
  }
  return kernel;
}

/// sigma(v) = -ln(1 - min(alpha(v), 1 - 1e-6)) / u, tabulated over the function's points
/// (linear between the table's nodes) and constant beyond them, so that it depends on the
/// function alone and never on the values a piece happens to hold.
class ExtinctionTable
{
public:
  ExtinctionTable(const OpacityFunction& function, double unit)
    : Function(function)
    , Unit(unit)
    , Low(function.nodes.front().x)
    , High(function.nodes.back().x)
  {
    const double margin = std::max(1.0, this->High - this->Low);
    this->Below = this->exact(this->Low - margin);
    this->Above = this->exact(this->High + margin);
    if (this->High > this->Low)
    {
      this->Values.resize(kTableCells + 1);
      for (int i = 0; i <= kTableCells; ++i)
        this->Values[static_cast<std::size_t>(i)] =
          this->exact(this->Low + (this->High - this->Low) * i / kTableCells);
      this->Scale = kTableCells / (this->High - this->Low);
    }
  }

  double operator()(double v) const
  {
    if (v < this->Low)
      return this->Below;
    if (v > this->High)
      return this->Above;
    if (this->Values.empty())
      return this->exact(v);
    const double t = (v - this->Low) * this->Scale;
    const int i = std::min(static_cast<int>(t), kTableCells - 1);
    const double f = t - i;
    const double a = this->Values[static_cast<std::size_t>(i)];
    return a + f * (this->Values[static_cast<std::size_t>(i) + 1] - a);
  }

private:
  double exact(double v) const
  {
    return -std::log1p(-std::min(evaluateOpacity(this->Function, v), 1.0 - 1e-6)) / this->Unit;
  }

  const OpacityFunction& Function;
  double Unit;
  double Low, High;
  double Below = 0.0, Above = 0.0;
  double Scale = 0.0;
  std::vector<double> Values;
};

/// A near sample's place relative to every voxel: the lattice step times its fraction is
/// the cell `corner` (whole voxels) plus `within` (in [0, 1) per axis), the same for all
/// voxels, so its trilinear weights and reads are fixed; `reads` are the linear offsets of
/// the cell's corners that carry weight (x fastest), `weights` theirs.
struct NearPlace
{
  std::array<std::int64_t, 3> corner{};
  std::array<bool, 3> between{}; // within > 0: the far corner along the axis is read
  int count = 0;
  std::array<std::int64_t, 8> reads{};
  std::array<double, 8> weights{};
  double length = 0.0;
};

NearPlace placeOf(
  const NearSample& sample, const std::array<int, 3>& step, const Index3& dims, std::int64_t stride)
{
  NearPlace place;
  place.length = sample.length;
  std::array<double, 3> within{};
  for (int a = 0; a < 3; ++a)
  {
    const double at = sample.fraction * step[a];
    place.corner[a] = static_cast<std::int64_t>(std::floor(at));
    within[a] = at - static_cast<double>(place.corner[a]);
    place.between[a] = within[a] > 0.0;
  }
  for (int c = 0; c < 8; ++c)
  {
    double weight = 1.0;
    std::int64_t offset = 0;
    bool used = true;
    for (int a = 0; a < 3; ++a)
    {
      const bool far = (c >> a) & 1;
      if (far && !place.between[a])
        used = false;
      weight *= far ? within[a] : 1.0 - within[a];
      const std::int64_t axisStride = a == 0 ? 1 : a == 1 ? dims[0] : dims[0] * dims[1];
      offset += (place.corner[a] + (far ? 1 : 0)) * axisStride;
    }
    if (used)
    {
      place.reads[static_cast<std::size_t>(place.count)] = offset * stride;
      place.weights[static_cast<std::size_t>(place.count)] = weight;
      ++place.count;
    }
  }
  return place;
}

/// Float grids of the block grown by `pad` cells on each side (zero there).
struct PaddedGrid
{
  Index3 dims{};
  std::array<int, 3> pad{};
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    const std::int64_t nx = dims[0] + 2 * pad[0], ny = dims[1] + 2 * pad[1];
    return ((z + pad[2]) * ny + (y + pad[1])) * nx + (x + pad[0]);
  }
  std::int64_t size() const
  {
    return (dims[0] + 2 * pad[0]) * (dims[1] + 2 * pad[1]) * (dims[2] + 2 * pad[2]);
  }
  bool holds(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    return x >= -pad[0] && x < dims[0] + pad[0] && y >= -pad[1] && y < dims[1] + pad[1] &&
      z >= -pad[2] && z < dims[2] + pad[2];
  }
};

/// The cell mean of the extinction: the mean of sigma at the 8 points (+-1/4, +-1/4, +-1/4)
/// of the cell, each value interpolated from the voxel and its neighbour (3/4 and 1/4 per
/// axis); a point outside the block counts 0.
template <class T>
bool cellMeans(const TypedVolume<T>& volume, const ExtinctionTable& sigma, const PaddedGrid& grid,
  float* out, const Execution& execution)
{
  const Index3& n = volume.dims;
  const int threads = resolveThreadCount(execution.threads);
  return parallelFor(n[2], static_cast<int>(std::min<std::int64_t>(n[2], 32 * threads)), threads,
    execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      for (std::int64_t z = begin; z < end; ++z)
      {
        for (std::int64_t y = 0; y < n[1]; ++y)
          for (std::int64_t x = 0; x < n[0]; ++x)
          {
            const std::int64_t at[3] = { x, y, z };
            double sum = 0.0;
            for (int corner = 0; corner < 8; ++corner)
            {
              std::int64_t other[3];
              bool inside = true;
              for (int a = 0; a < 3; ++a)
              {
                other[a] = at[a] + (((corner >> a) & 1) ? 1 : -1);
                inside = inside && other[a] >= 0 && other[a] < n[a];
              }
              if (!inside)
                continue;
              double value = 0.0;
              for (int c = 0; c < 8; ++c)
              {
                double weight = 1.0;
                std::int64_t p[3];
                for (int a = 0; a < 3; ++a)
                {
                  const bool far = (c >> a) & 1;
                  weight *= far ? 0.25 : 0.75;
                  p[a] = far ? other[a] : at[a];
                }
                value += weight * static_cast<double>(volume.value(p[0], p[1], p[2]));
              }
              sum += sigma(value);
            }
            out[grid.index(x, y, z)] = static_cast<float>(sum / 8.0);
          }
        if (!progress.advance())
          return;
      }
    });
}

/// One separable box pass along `axis` over the whole padded grid: out = kernel * in.
bool boxPass(const PaddedGrid& grid, int axis, const std::vector<double>& kernel, const float* in,
  float* out, const Execution& execution)
{
  const std::int64_t full[3] = { grid.dims[0] + 2 * grid.pad[0], grid.dims[1] + 2 * grid.pad[1],
    grid.dims[2] + 2 * grid.pad[2] };
  const std::int64_t stride = axis == 0 ? 1 : axis == 1 ? full[0] : full[0] * full[1];
  const int half = static_cast<int>(kernel.size() / 2);
  const int threads = resolveThreadCount(execution.threads);
  return parallelFor(full[2], static_cast<int>(std::min<std::int64_t>(full[2], 32 * threads)),
    threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      for (std::int64_t z = begin; z < end; ++z)
      {
        for (std::int64_t y = 0; y < full[1]; ++y)
          for (std::int64_t x = 0; x < full[0]; ++x)
          {
            const std::int64_t at[3] = { x, y, z };
            const std::int64_t i = (z * full[1] + y) * full[0] + x;
            double sum = 0.0;
            for (int o = -half; o <= half; ++o)
            {
              const std::int64_t c = at[axis] + o;
              if (c >= 0 && c < full[axis])
                sum += kernel[static_cast<std::size_t>(o + half)] * in[i + o * stride];
            }
            out[i] = static_cast<float>(sum);
          }
        if (!progress.advance())
          return;
      }
    });
}

template <class T>
bool estimate(const VolumeView& view, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, ConcurrentRange* seen,
  const Execution& execution)
{
  const TypedVolume<T> volume(view);
  const RayPlan plan = planRays(parameters.rays);
  const ExtinctionTable sigma(parameters.opacity, plan.unit);
  const std::array<double, 3>& h = parameters.rays.spacing;
  // The levels the cones read, their kernels along each axis, and the padding they spread to.
  std::vector<bool> used(static_cast<std::size_t>(kLevels), false);
  for (const LatticeCone& cone : plan.cones)
    for (const FarSample& sample : cone.far)
      used[static_cast<std::size_t>(sample.level)] = true;
  std::vector<std::array<std::vector<double>, 3>> kernels(static_cast<std::size_t>(kLevels));
  PaddedGrid grid;
  grid.dims = view.dims;
  for (int l = 1; l < kLevels; ++l)
    for (int a = 0; a < 3; ++a)
      if (used[static_cast<std::size_t>(l)])
      {
        kernels[static_cast<std::size_t>(l)][a] = boxKernel(plan.levelSides[l] / h[a]);
        grid.pad[a] = std::max(
          grid.pad[a], static_cast<int>(kernels[static_cast<std::size_t>(l)][a].size() / 2));
      }
  std::vector<std::vector<float>> levels(static_cast<std::size_t>(kLevels));
  levels[0].assign(static_cast<std::size_t>(grid.size()), 0.0f);
  if (!cellMeans(volume, sigma, grid, levels[0].data(), stageExecution(execution, 0.0, 0.1)))
    return false;
  std::vector<float> scratch;
  for (int l = 1; l < kLevels; ++l)
  {
    if (!used[static_cast<std::size_t>(l)])
      continue;
    const Execution stage = stageExecution(execution, 0.1 + 0.04 * (l - 1), 0.1 + 0.04 * l);
    std::vector<float> current = levels[0];
    scratch.resize(current.size());
    for (int a = 0; a < 3; ++a)
    {
      const std::vector<double>& kernel = kernels[static_cast<std::size_t>(l)][a];
      if (kernel.empty())
        continue;
      if (!boxPass(grid, a, kernel, current.data(), scratch.data(), stage))
        return false;
      current.swap(scratch);
    }
    levels[static_cast<std::size_t>(l)] = std::move(current);
  }
  const Index3& n = view.dims;
  // Every sample's fixed offsets: the near samples' corners in the volume, the far
  // samples' cells in the padded grids.
  std::vector<std::vector<NearPlace>> nearPlaces(plan.cones.size());
  std::vector<std::vector<std::int64_t>> farOffsets(plan.cones.size());
  for (std::size_t c = 0; c < plan.cones.size(); ++c)
  {
    const LatticeCone& cone = plan.cones[c];
    for (const NearSample& sample : cone.near)
      nearPlaces[c].push_back(placeOf(sample, cone.step, n, volume.stride));
    for (const FarSample& sample : cone.far)
      farOffsets[c].push_back(
        grid.index(std::int64_t(sample.step) * cone.step[0],
          std::int64_t(sample.step) * cone.step[1], std::int64_t(sample.step) * cone.step[2]) -
        grid.index(0, 0, 0));
  }
  const std::int64_t nx = region.size[0];
  const std::int64_t rows = region.size[1] * region.size[2];
  const int threads = resolveThreadCount(execution.threads);
  return parallelFor(rows,
    static_cast<int>(std::min<std::int64_t>(rows, 64 * std::int64_t(threads))), threads,
    stageExecution(execution, 0.3, 1.0),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      // A row at a time, cone by cone: each sample's reads are then contiguous along x.
      std::vector<double> nearDepth(static_cast<std::size_t>(nx));
      std::vector<double> farDepth(static_cast<std::size_t>(nx));
      std::vector<double> ao(static_cast<std::size_t>(nx));
      const std::int64_t x0 = region.begin[0];
      for (std::int64_t row = begin; row < end; ++row)
      {
        const std::int64_t y = region.begin[1] + row % region.size[1];
        const std::int64_t z = region.begin[2] + row / region.size[1];
        const T* rowStart = volume.data + volume.index(x0, y, z) * volume.stride;
        const std::int64_t cellStart = grid.index(x0, y, z);
        std::fill(ao.begin(), ao.end(), 0.0);
        for (std::size_t c = 0; c < plan.cones.size(); ++c)
        {
          const LatticeCone& cone = plan.cones[c];
          std::fill(nearDepth.begin(), nearDepth.end(), 0.0);
          for (const NearPlace& place : nearPlaces[c])
          {
            // The sample lies in the block: along y and z for the whole row, along x
            // for the voxels [from, to).
            const std::int64_t cy = y + place.corner[1], cz = z + place.corner[2];
            if (cy < 0 || cy + (place.between[1] ? 1 : 0) > n[1] - 1 || cz < 0 ||
              cz + (place.between[2] ? 1 : 0) > n[2] - 1)
              continue;
            const std::int64_t from = std::max<std::int64_t>(0, -place.corner[0] - x0);
            const std::int64_t to =
              std::min<std::int64_t>(nx, n[0] - (place.between[0] ? 1 : 0) - place.corner[0] - x0);
            for (std::int64_t i = from; i < to; ++i)
            {
              const T* at = rowStart + i * volume.stride;
              double value = 0.0;
              for (int k = 0; k < place.count; ++k)
                value += place.weights[static_cast<std::size_t>(k)] *
                  static_cast<double>(at[place.reads[static_cast<std::size_t>(k)]]);
              nearDepth[static_cast<std::size_t>(i)] += place.length * sigma(value);
            }
          }
          std::fill(farDepth.begin(), farDepth.end(), 0.0);
          for (std::size_t f = 0; f < cone.far.size(); ++f)
          {
            const FarSample& sample = cone.far[f];
            const std::int64_t qy = y + std::int64_t(sample.step) * cone.step[1];
            const std::int64_t qz = z + std::int64_t(sample.step) * cone.step[2];
            const std::int64_t dx = std::int64_t(sample.step) * cone.step[0];
            if (!grid.holds(0, qy, qz))
              continue;
            const std::int64_t from = std::max<std::int64_t>(0, -grid.pad[0] - dx - x0);
            const std::int64_t to = std::min<std::int64_t>(nx, n[0] + grid.pad[0] - dx - x0);
            const float* level =
              levels[static_cast<std::size_t>(sample.level)].data() + cellStart + farOffsets[c][f];
            for (std::int64_t i = from; i < to; ++i)
              farDepth[static_cast<std::size_t>(i)] += sample.length * level[i];
          }
          // A cone along the volume's face, from a voxel on it: its lattice line stays
          // inside while half of the cone leaves into open sky.
          int faces = 0;
          if (cone.step[1] == 0 && (y == 0 || y == n[1] - 1))
            ++faces;
          if (cone.step[2] == 0 && (z == 0 || z == n[2] - 1))
            ++faces;
          for (std::int64_t i = 0; i < nx; ++i)
          {
            const double g = 1.0 + farDepth[static_cast<std::size_t>(i)] / kFarGamma;
            double transmitted =
              std::exp(-nearDepth[static_cast<std::size_t>(i)]) / ((g * g) * (g * g));
            const bool xFace = cone.step[0] == 0 && (x0 + i == 0 || x0 + i == n[0] - 1);
            for (int k = 0; k < faces + (xFace ? 1 : 0); ++k)
              transmitted = 0.5 * (1.0 + transmitted);
            ao[static_cast<std::size_t>(i)] += cone.weight * transmitted;
          }
        }
        float* out = openness + row * nx;
        for (std::int64_t i = 0; i < nx; ++i)
          out[i] =
            static_cast<float>(std::min(1.0, std::max(0.0, ao[static_cast<std::size_t>(i)])));
        if (seen)
          seen->add(out, nx);
        if (!progress.advance())
          return;
      }
    });
}

} // namespace

} // namespace detail

std::array<int, 3> rayEstimateReach(const RayParameters& rays)
{
  return detail::planRays(rays).reach;
}

namespace detail
{

RayPlan planRays(const RayParameters& rays)
{
  static_assert(kFarGamma == 4.0, "the far transmittance is written for K = 4");
  RayPlan plan;
  const std::array<double, 3>& h = rays.spacing;
  const double smallest = std::min({ h[0], h[1], h[2] });
  const double largest = std::max({ h[0], h[1], h[2] });
  plan.unit = rays.opacityUnitDistance > 0.0 ? rays.opacityUnitDistance : smallest;
  for (double side : kLevelSides)
    plan.levelSides.push_back(side * smallest);
  const double radius = rays.radius;
  // Anisotropic voxels: the index steps are stretched so that the cones' world directions
  // stay close to those of cubic voxels.
  int stretch[3];
  for (int a = 0; a < 3; ++a)
    stretch[a] = std::max(1, static_cast<int>(std::lround(largest / h[a])));
  std::vector<std::array<double, 3>> axes;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
      {
        if (dx == 0 && dy == 0 && dz == 0)
          continue;
        std::array<int, 3> step = { dx * stretch[0], dy * stretch[1], dz * stretch[2] };
        const int g = std::gcd(std::gcd(std::abs(step[0]), std::abs(step[1])), std::abs(step[2]));
        for (int& s : step)
          s /= g;
        LatticeCone cone;
        cone.step = step;
        // World vector of one step: D diag(h) step.
        std::array<double, 3> world{};
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            world[r] += rays.direction[3 * r + c] * h[c] * step[c];
        const double length =
          std::sqrt(world[0] * world[0] + world[1] * world[1] + world[2] * world[2]);
        axes.push_back({ world[0] / length, world[1] / length, world[2] / length });
        // Near part: the first step (or the radius), in an even number of samples.
        const int halves = 2 *
          std::max(1, static_cast<int>(std::ceil(length / smallest / (2.0 * kNearSpacing) - 1e-9)));
        const double nearEnd = std::min(length, radius);
        for (int i = 0; i * length / halves < nearEnd - 1e-9 * nearEnd; ++i)
        {
          const double from = i * length / halves;
          cone.near.push_back({ (2.0 * i + 1.0) / (2.0 * halves),
            std::min((i + 1) * length / halves, nearEnd) - from });
        }
        // Far part: lattice points standing for the segments half way to their neighbours.
        if (nearEnd < radius * (1.0 - 1e-9))
        {
          const int last = std::max(1, static_cast<int>(std::ceil(radius / length - 0.5 - 1e-9)));
          const std::vector<int> steps = farSteps(last);
          for (std::size_t q = 0; q < steps.size(); ++q)
          {
            const double from = q == 0 ? nearEnd : 0.5 * (steps[q - 1] + steps[q]) * length;
            const double to = q + 1 < steps.size()
              ? std::min(0.5 * (steps[q] + steps[q + 1]) * length, radius)
              : radius;
            if (!(to > from))
              continue;
            const double side = std::max(1.0, kConeWidth * steps[q] * length / smallest);
            int level = kLevels - 1;
            for (int l = 0; l < kLevels; ++l)
              if (kLevelSides[l] >= side - 1e-9)
              {
                level = l;
                break;
              }
            cone.far.push_back({ steps[q], level, to - from });
          }
        }
        plan.cones.push_back(std::move(cone));
      }
  // Each cone's share: the Fibonacci directions nearest to its world direction.
  std::vector<int> nearest(plan.cones.size(), 0);
  for (const std::array<double, 3>& w : fibonacciDirections(kWeightDirections))
  {
    std::size_t best = 0;
    double bestDot = -2.0;
    for (std::size_t c = 0; c < axes.size(); ++c)
    {
      const double dot = w[0] * axes[c][0] + w[1] * axes[c][1] + w[2] * axes[c][2];
      if (dot > bestDot)
      {
        bestDot = dot;
        best = c;
      }
    }
    ++nearest[best];
  }
  // Opposite cones span the same solid angle: their counts are averaged, which halves the
  // sampling's noise and keeps the estimate symmetric (the cones come in opposite pairs,
  // cone c opposite cone 25 - c).
  for (std::size_t c = 0; c < plan.cones.size(); ++c)
    plan.cones[c].weight = static_cast<double>(nearest[c] + nearest[plan.cones.size() - 1 - c]) /
      (2.0 * kWeightDirections);
  // What a result reads: the near samples' cells, the far samples' blurred cells (the
  // blur's half-width, the cell means' neighbours).
  for (const LatticeCone& cone : plan.cones)
    for (int a = 0; a < 3; ++a)
    {
      int reach = std::abs(cone.step[a]);
      for (const FarSample& sample : cone.far)
      {
        const int blur =
          static_cast<int>(boxKernel(plan.levelSides[sample.level] / h[a]).size() / 2);
        reach = std::max(reach, sample.step * std::abs(cone.step[a]) + blur + 1);
      }
      plan.reach[a] = std::max(plan.reach[a], reach);
    }
  return plan;
}

Status computeRays(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, OutputRange* range,
  const Execution& execution)
{
  return keepingOutputRange(volume.type, range,
    [&](auto tag, ConcurrentRange* seen)
    { return estimate<decltype(tag)>(volume, region, parameters, openness, seen, execution); });
}

} // namespace detail
} // namespace vao
