// The stages of occlusion sweeping around the sweeps: checking the request, the initial
// distance field and its fixed voxels, and the combination of the octant visibilities
// into the outputs (Singh et al. Eq. 4/5).
#include "cpu/occlusion_sweeping/SweepingCore.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"
#include "vao/Validation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace vao
{
namespace detail
{
namespace sweeping
{
namespace
{

constexpr double kPi = 3.14159265358979323846;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

/// (c - v) / (w - v), the fraction of the edge from v to w where it crosses c, also for
/// values near the largest doubles, whose differences overflow: then of the halves
/// (exact), which cannot.
double crossingFraction(double c, double v, double w)
{
  const double across = w - v;
  if (std::isfinite(across))
  {
    return (c - v) / across;
  }
  return (0.5 * c - 0.5 * v) / (0.5 * w - 0.5 * v);
}

/// The number of octants lit.
int litOctants(const SweepParameters& p)
{
  return static_cast<int>(std::count(p.octantMask.begin(), p.octantMask.end(), true));
}

} // namespace

double sweepUnit(const std::array<double, 3>& spacing)
{
  return std::ldexp(1.0, std::ilogb(std::min({ spacing[0], spacing[1], spacing[2] })));
}

std::array<double, 3> inSweepUnits(const std::array<double, 3>& spacing)
{
  const double unit = sweepUnit(spacing);
  return { spacing[0] / unit, spacing[1] / unit, spacing[2] / unit };
}

Status validateSweepParameters(
  const std::array<double, 3>& spacing, const SweepParameters& p, const SweepOutput& output)
{
  Status status = checkSpacing(spacing);
  if (status.ok)
    status = checkFiniteParameter(p.isoValue, "the iso value");
  if (!status.ok)
    return status;
  std::ostringstream why;
  const auto [smallest, largest] = std::minmax({ spacing[0], spacing[1], spacing[2] });
  if (smallest < kSmallestSpacing || largest > kLargestSpacing)
  {
    why << "occlusion sweeping needs spacings between " << kSmallestSpacing << " and "
        << kLargestSpacing << " (its distances are float; got " << spacing[0] << ", " << spacing[1]
        << ", " << spacing[2] << "): rescale the volume (e.g. with Change Spacing)";
  }
  else if (p.iterations < 1)
  {
    why << "at least one pass of the 8 sweeps is needed (iterations = " << p.iterations << ")";
  }
  else if (!std::isfinite(p.tolerance) || p.tolerance < 0.0)
  {
    why << "the tolerance must be finite and not negative (got " << p.tolerance << ")";
  }
  else if (!std::isfinite(p.gamma) || !(p.gamma > 0.0))
  {
    why << "gamma must be finite and positive (got " << p.gamma << ")";
  }
  else if (!(p.opacity >= 0.0 && p.opacity <= 1.0))
  {
    why << "the opacity must lie in [0, 1] (got " << p.opacity << ")";
  }
  else if (output.ambientOcclusion && litOctants(p) == 0)
  {
    why << "every octant is masked off, so the ambient occlusion is undefined";
  }
  const std::string message = why.str();
  return message.empty() ? Status::success() : Status::failure(message);
}

Status validateSweep(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& p, const SweepOutput& output)
{
  Status status = checkVolume(volume, 2, "occlusion sweeping");
  if (status.ok)
    status = validateSweepParameters(spacing, p, output);
  if (status.ok)
    status = checkFiniteValues(volume);
  return status;
}

namespace
{

/// D of the grid points next to the iso surface: on every axis edge whose ends straddle
/// the iso value, the linearly interpolated distance to the crossing (the minimum over the
/// point's edges); these points are fixed. All others get +-infinity. The distance is
/// computed from each point's own end of the edge, so that mirrored data give mirrored
/// bits. Returns the number of fixed points.
template <class T>
std::int64_t initialiseDistanceOf(const VolumeView& view, const Index3& scalarOffset,
  const SweepLayout& layout, const SweepParameters& p, float* distance, int threads)
{
  const detail::TypedVolume<T> volume(view);
  const double c = p.isoValue;
  const bool above = p.insideIsAbove;
  auto inside = [c, above](double v) { return above ? v > c : v < c; };
  const Index3& extent = view.dims;
  const std::int64_t steps[3] = { 1, extent[0], extent[0] * extent[1] };
  const std::array<double, 3>& h = layout.storage.h;
  std::atomic<std::int64_t> fixedCount{ 0 };
  detail::parallelFor(layout.size[2], threads, threads,
    [&](std::int64_t z0, std::int64_t z1)
    {
      std::int64_t local = 0;
      for (std::int64_t z = z0; z < z1; ++z)
        for (std::int64_t y = 0; y < layout.size[1]; ++y)
          for (std::int64_t x = 0; x < layout.size[0]; ++x)
          {
            const std::int64_t position[3] = { x + scalarOffset[0], y + scalarOffset[1],
              z + scalarOffset[2] };
            const std::int64_t i = volume.index(position[0], position[1], position[2]);
            const double v = static_cast<double>(volume.data[i * volume.stride]);
            const bool in = inside(v);
            double nearest = std::numeric_limits<double>::infinity();
            for (int a = 0; a < 3; ++a)
              for (int side = -1; side <= 1; side += 2)
              {
                const std::int64_t q = position[a] + side;
                if (q < 0 || q >= extent[a])
                  continue;
                const double w =
                  static_cast<double>(volume.data[(i + side * steps[a]) * volume.stride]);
                if (inside(w) != in)
                  nearest = std::min(nearest, crossingFraction(c, v, w) * h[a]);
              }
            const bool isFixed = nearest < std::numeric_limits<double>::infinity();
            const float magnitude = isFixed ? static_cast<float>(nearest) : kInfinity;
            const std::int64_t o = layout.index(x, y, z);
            distance[o] = in ? -magnitude : magnitude;
            local += isFixed;
          }
      fixedCount += local;
    });
  return fixedCount.load();
}

} // namespace

std::int64_t initialiseDistance(const VolumeView& scalars, const Index3& scalarOffset,
  const SweepLayout& layout, const SweepParameters& p, float* distance, int threads)
{
  return detail::dispatchScalarType(scalars.type,
    [&](auto tag)
    {
      return initialiseDistanceOf<decltype(tag)>(
        scalars, scalarOffset, layout, p, distance, threads);
    });
}

void FixedMask::build(const float* distance, std::int64_t count, int threads)
{
  const std::int64_t words = (count + 63) / 64;
  this->Words.assign(static_cast<std::size_t>(words), 0);
  std::uint64_t* out = this->Words.data();
  detail::parallelFor(words, threads, threads,
    [&](std::int64_t w0, std::int64_t w1)
    {
      for (std::int64_t w = w0; w < w1; ++w)
      {
        std::uint64_t bits = 0;
        const std::int64_t end = std::min<std::int64_t>(64, count - 64 * w);
        for (std::int64_t b = 0; b < end; ++b)
          bits |= std::uint64_t(std::abs(distance[64 * w + b]) < kInfinity) << b;
        out[w] = bits;
      }
    });
}

namespace
{

// ---------------------------------------------------------------------------------------
// Combination into the outputs

/// N at own voxel (x, y, z): the normalised central-difference gradient of D (one-sided at
/// the whole volume's borders; a block reads its ghost layer elsewhere), pointing outward.
std::array<double, 3> distanceNormal(
  const float* d, const SweepLayout& layout, std::int64_t x, std::int64_t y, std::int64_t z)
{
  const Grid& g = layout.storage;
  const std::int64_t position[3] = { layout.begin[0] + x, layout.begin[1] + y,
    layout.begin[2] + z };
  const Index3& extent = layout.whole;
  const std::int64_t step[3] = { 1, g.nx, g.plane };
  const std::int64_t i = layout.index(x, y, z);
  double gradient[3];
  for (int a = 0; a < 3; ++a)
  {
    const std::int64_t lo = position[a] > 0 ? -1 : 0;
    const std::int64_t hi = position[a] + 1 < extent[a] ? 1 : 0;
    gradient[a] =
      (static_cast<double>(d[i + hi * step[a]]) - d[i + lo * step[a]]) / ((hi - lo) * g.h[a]);
  }
  return unitNormal(gradient[0], gradient[1], gradient[2]);
}

struct Combiner
{
  const SweepLayout& layout;
  const SweepParameters& p;
  const SweepOutput& out;
  const float* distance;
  const VisibilityStore& vis;
  double maskCount;

  /// The unclamped A of own voxel (x, y, z) with the geometry term, whose octants' V are v.
  double weightedOcclusion(const float* v, std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    const bool twoSided = this->p.opacity < 1.0;
    double g[8];
    allGeometryTerms(distanceNormal(this->distance, this->layout, x, y, z), twoSided, g);
    double sum = 0.0;
    for (int s = 0; s < 8; ++s)
      if (this->p.octantMask[s])
        sum += v[s] * g[s];
    return sum / (twoSided ? 2.0 * kPi : kPi);
  }

  /// Own plane z. `rows` holds a row of the eight fields while the row-interleaved output
  /// (VisibilityStore::inOutput) is transposed in place; `occlusion`, a row of A. Each
  /// step is a loop over the row, which the compiler vectorises where it has no call.
  void plane(std::int64_t z, std::vector<float>& rows, std::vector<double>& occlusion) const
  {
    const Index3& n = this->layout.size;
    occlusion.resize(static_cast<std::size_t>(n[0]));
    for (std::int64_t y = 0; y < n[1]; ++y)
    {
      const std::int64_t first = this->layout.index(0, y, z);
      const std::int64_t o = (z * n[1] + y) * n[0]; // the row's first output voxel
      if (this->vis.inOutput)
      {
        const float* block =
          this->vis.field[0] + (z * n[1] + y) * this->vis.rowPitch; // whole volume
        rows.assign(block, block + 8 * n[0]);
      }
      // Row y of each octant's field (null where not computed: V = 0).
      const float* field[8] = {};
      for (int s = 0; s < 8 && this->vis.kept; ++s)
        field[s] = this->vis.inOutput ? rows.data() + s * n[0]
          : this->vis.field[s]        ? this->vis.field[s] + first
                                      : nullptr;
      if (this->out.octantVisibility)
      {
        for (std::int64_t x = 0; x < n[0]; ++x)
          for (int s = 0; s < 8; ++s)
            this->out.octantVisibility[8 * (o + x) + s] = field[s] ? field[s][x] : 0.0f;
      }
      if (this->out.ambientOcclusion)
        this->occlusionRow(field, first, o, y, z, occlusion.data());
    }
  }

  /// Row y of plane z's AmbientOcclusion (Eq. 4/5, clamped, to the power 1 / gamma).
  void occlusionRow(const float* const* field, std::int64_t first, std::int64_t o, std::int64_t y,
    std::int64_t z, double* __restrict a) const
  {
    const std::int64_t n = this->layout.size[0];
    if (!this->vis.kept)
    {
      const float* sum = this->vis.sum + first;
      for (std::int64_t x = 0; x < n; ++x)
        a[x] = sum[x] / this->maskCount;
    }
    else if (!this->p.useGeometryTerm)
    {
      // The masked octants' V summed in octant order, as the geometry's sum.
      std::fill(a, a + n, 0.0);
      for (int s = 0; s < 8; ++s)
        if (this->p.octantMask[s] && field[s])
        {
          const float* __restrict v = field[s];
          for (std::int64_t x = 0; x < n; ++x)
            a[x] += v[x];
        }
      for (std::int64_t x = 0; x < n; ++x)
        a[x] /= this->maskCount;
    }
    else
    {
      for (std::int64_t x = 0; x < n; ++x)
      {
        float v[8];
        for (int s = 0; s < 8; ++s)
          v[s] = field[s] ? field[s][x] : 0.0f;
        a[x] = this->weightedOcclusion(v, x, y, z);
      }
    }
    for (std::int64_t x = 0; x < n; ++x)
      a[x] = std::min(1.0, std::max(0.0, a[x]));
    const double exponent = 1.0 / this->p.gamma;
    if (exponent == 0.5) // the paper's gamma 2, fast
    {
      for (std::int64_t x = 0; x < n; ++x)
        a[x] = std::sqrt(a[x]);
    }
    else if (exponent != 1.0)
    {
      for (std::int64_t x = 0; x < n; ++x)
        a[x] = std::pow(a[x], exponent);
    }
    float* __restrict ao = this->out.ambientOcclusion + o;
    for (std::int64_t x = 0; x < n; ++x)
      ao[x] = static_cast<float>(a[x]);
  }
};

} // namespace

void fillWithoutSurface(const SweepLayout& layout, bool allInside, float* distance,
  VisibilityStore& vis, double maskCount)
{
  const double diagonal = Grid(layout.whole, layout.storage.h).diagonal();
  const float d = static_cast<float>(allInside ? -diagonal : diagonal);
  const float v = allInside ? 0.0f : 1.0f;
  const std::int64_t count = layout.storage.count;
  std::fill(distance, distance + count, d);
  if (vis.inOutput)
  {
    std::fill(vis.field[0], vis.field[0] + 8 * count, v);
  }
  else if (vis.kept)
  {
    for (float* field : vis.field)
      if (field)
        std::fill(field, field + count, v);
  }
  else if (vis.sum)
  {
    std::fill(vis.sum, vis.sum + count, static_cast<float>(v * maskCount));
  }
}
Status combine(const SweepLayout& layout, const SweepParameters& p, const SweepOutput& out,
  const float* distance, const VisibilityStore& vis, double maskCount, int threads,
  const Execution& execution)
{
  if (!out.ambientOcclusion && !out.octantVisibility)
  {
    return Status::success();
  }
  const Combiner combiner{ layout, p, out, distance, vis, maskCount };
  const bool finished = detail::parallelFor(layout.size[2], threads, threads, execution,
    [&](std::int64_t z0, std::int64_t z1, detail::ChunkProgress& progress)
    {
      std::vector<float> rows;
      std::vector<double> occlusion;
      for (std::int64_t z = z0; z < z1 && !progress.stopped(); ++z)
      {
        combiner.plane(z, rows, occlusion);
        progress.advance();
      }
    });
  return finished ? Status::success() : Status::cancelled();
}

} // namespace sweeping
} // namespace detail
} // namespace vao
