// The smoothed query (docs/methods.md section 9): a normalised, truncated Gaussian average of v.
//
// The window of half-width ceil(3 sigma) clipped to the volume is a product of clipped
// intervals and the weight a product of 1-D Gaussians, so the normalised 3-D average is
// three normalised 1-D averages, one per axis (x, then y, then z). Each pass is written as
// centre + sum_i w_i (v_i - centre) with weights that sum to 1: the same value in exact
// arithmetic, and exactly the centre's value where the window is flat. Each thread streams
// its slices through a ring of 2 ceil(3 sigma) + 1 planes smoothed in x and y.
#include "cpu/smoothed_query/SmoothedQuery.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{
namespace
{

/// Normalised weights of one axis for each output coordinate: window [first, first + size).
struct AxisWeights
{
  std::int64_t half = 0;
  std::vector<std::int64_t> first, size;
  std::vector<double> weights; // (2 half + 1) per output coordinate, the first `size` used

  AxisWeights(std::int64_t begin, std::int64_t count, std::int64_t n, double sigma)
  {
    half = std::min<std::int64_t>(querySmoothingHalfWidth(sigma), n - 1);
    const std::int64_t taps = 2 * half + 1;
    first.resize(count);
    size.resize(count);
    weights.assign(static_cast<std::size_t>(count * taps), 0.0);
    for (std::int64_t i = 0; i < count; ++i)
    {
      const std::int64_t c = begin + i;
      const std::int64_t lo = std::max<std::int64_t>(0, c - half);
      const std::int64_t hi = std::min<std::int64_t>(n - 1, c + half);
      first[i] = lo;
      size[i] = hi - lo + 1;
      double* w = &weights[i * taps];
      double total = 0.0;
      for (std::int64_t y = lo; y <= hi; ++y)
      {
        const double d = static_cast<double>(y - c);
        w[y - lo] = std::exp(-d * d / (2.0 * sigma * sigma));
        total += w[y - lo];
      }
      for (std::int64_t k = 0; k <= hi - lo; ++k)
      {
        w[k] /= total;
      }
    }
  }

  const double* of(std::int64_t i) const { return &weights[i * (2 * half + 1)]; }
};

/// centre + sum_k w_k (v[first + k] - centre), values read through `at`.
template <class At>
double centredAverage(
  double centre, const double* w, std::int64_t first, std::int64_t size, At&& at)
{
  double sum = 0.0;
  for (std::int64_t k = 0; k < size; ++k)
  {
    sum += w[k] * (at(first + k) - centre);
  }
  return centre + sum;
}

/// Integer data: a query within rounding of an integer is that integer, so that a flat or
/// symmetric window counts its own value as <= q whatever the order of the sums. Within
/// 1e-9 of it relative to its magnitude, but never more than 1e-6 away: at 1e9 the relative
/// bound alone would take every query to an integer (the CT head with an offset of 1e9
/// then gave Exact Box counts up to 0.24 off).
double snapToInteger(double q)
{
  const double r = std::nearbyint(q);
  return std::abs(q - r) <= std::min(1e-9 * std::max(1.0, std::abs(r)), 1e-6) ? r : q;
}

template <class T>
class QueryPlanes
{
public:
  QueryPlanes(const TypedVolume<T>& volume, const Region& region, const AxisWeights& wx,
    const AxisWeights& wy, const AxisWeights& wz)
    : Volume(volume)
    , Out(region)
    , Wx(wx)
    , Wy(wy)
    , Wz(wz)
    , YLo(std::max<std::int64_t>(0, region.begin[1] - wy.half))
    , YHi(std::min<std::int64_t>(volume.dims[1], region.begin[1] + region.size[1] + wy.half))
    , Rows(static_cast<std::size_t>((YHi - YLo) * region.size[0]))
    , Ring(static_cast<std::size_t>((2 * wz.half + 1) * region.size[0] * region.size[1]))
    , Held(static_cast<std::size_t>(2 * wz.half + 1), -1)
  {
  }

  /// q of output slice z into out (the region's plane, x fastest).
  void slice(std::int64_t z, double* out)
  {
    const std::int64_t k = z - this->Out.begin[2];
    const std::int64_t first = this->Wz.first[k], size = this->Wz.size[k];
    const std::int64_t plane = this->Out.size[0] * this->Out.size[1];
    for (std::int64_t s = first; s < first + size; ++s)
    {
      this->smoothPlane(s);
    }
    const double* centre = this->planeOf(z);
    const double* w = this->Wz.of(k);
    for (std::int64_t p = 0; p < plane; ++p)
    {
      const double q = centredAverage(
        centre[p], w, first, size, [&](std::int64_t s) { return this->planeOf(s)[p]; });
      out[p] = std::is_integral<T>::value ? snapToInteger(q) : q;
    }
  }

private:
  const double* planeOf(std::int64_t s) const
  {
    const std::int64_t plane = this->Out.size[0] * this->Out.size[1];
    return &this->Ring[(s % static_cast<std::int64_t>(this->Held.size())) * plane];
  }

  /// Smooths slice s in x and y into its ring slot, unless the slot holds it already.
  void smoothPlane(std::int64_t s)
  {
    const std::int64_t slot = s % static_cast<std::int64_t>(this->Held.size());
    if (this->Held[slot] == s)
    {
      return;
    }
    const std::int64_t nx = this->Out.size[0], ny = this->Out.size[1];
    for (std::int64_t y = this->YLo; y < this->YHi; ++y)
    {
      const T* row = this->Volume.row(y, s);
      const std::int64_t stride = this->Volume.stride;
      double* dst = &this->Rows[(y - this->YLo) * nx];
      for (std::int64_t i = 0; i < nx; ++i)
      {
        const double centre = static_cast<double>(row[(this->Out.begin[0] + i) * stride]);
        dst[i] = centredAverage(centre, this->Wx.of(i), this->Wx.first[i], this->Wx.size[i],
          [&](std::int64_t x) { return static_cast<double>(row[x * stride]); });
      }
    }
    double* plane = &this->Ring[slot * nx * ny];
    for (std::int64_t j = 0; j < ny; ++j)
    {
      const double* w = this->Wy.of(j);
      const std::int64_t first = this->Wy.first[j], size = this->Wy.size[j];
      const double* centre = &this->Rows[(this->Out.begin[1] + j - this->YLo) * nx];
      for (std::int64_t i = 0; i < nx; ++i)
      {
        plane[j * nx + i] = centredAverage(centre[i], w, first, size,
          [&](std::int64_t y) { return this->Rows[(y - this->YLo) * nx + i]; });
      }
    }
    this->Held[slot] = s;
  }

  const TypedVolume<T>& Volume;
  Region Out;
  const AxisWeights &Wx, &Wy, &Wz;
  std::int64_t YLo, YHi;
  std::vector<double> Rows;
  std::vector<double> Ring;
  std::vector<std::int64_t> Held; // the slice each ring slot holds (-1: none)
};

} // namespace

bool computeSmoothedQuery(const VolumeView& view, const Region& region, double sigma, double* query,
  const Execution& execution)
{
  const AxisWeights wx(region.begin[0], region.size[0], view.dims[0], sigma);
  const AxisWeights wy(region.begin[1], region.size[1], view.dims[1], sigma);
  const AxisWeights wz(region.begin[2], region.size[2], view.dims[2], sigma);
  const std::int64_t plane = region.size[0] * region.size[1];
  return dispatchScalarType(view.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const TypedVolume<T> volume(view);
      const int threads = resolveThreadCount(execution.threads);
      return parallelFor(region.size[2], threads, threads, execution,
        [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
        {
          QueryPlanes<T> planes(volume, region, wx, wy, wz);
          for (std::int64_t k = begin; k < end && !progress.stopped(); ++k)
          {
            planes.slice(region.begin[2] + k, query + k * plane);
            progress.advance();
          }
        });
    });
}

} // namespace detail
} // namespace vao
