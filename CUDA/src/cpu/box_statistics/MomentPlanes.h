// The box sums of v and v^2, streamed slice by slice along z.
//
// Each thread owns a chunk of output slices and keeps the 3-D box sums of v and v^2 for
// the current slice as a plane. Moving to the next slice adds the 2-D box sum of the slice
// that enters the window and subtracts the one that leaves; both are done in one x/y pass
// over the difference of the two slices (box sums are linear). Per voxel and slice this is
// O(1) whatever the radius, and only the input is read from memory and the output written:
// the x-box rows stay in cache (a ring of 2 r_y + 2 of them; the sums of squares of 8-bit
// and int16 rows in 32 bits where each fits, as on CT-like data), and the plane is read and
// written once per slice.
#pragma once

#include "VolumeAccess.h"
#include "cpu/box_statistics/PlaneRowKernels.h"
#include "cpu/box_statistics/RunningTotals.h"
#include "cpu/common/Parallel.h"
#include "cpu/simd/CpuDispatch.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace vao
{
namespace detail
{

/// Region geometry shared by the passes: spans read along each axis.
struct BoxGeometry
{
  Index3 dims;
  Region region;
  Radius radius;
  AxisSpan xs, ys, zs;

  BoxGeometry(const Index3& volumeDims, const Region& outputRegion, const Radius& r)
    : dims(volumeDims)
    , region(outputRegion)
    , radius(r)
    , xs(readSpan(outputRegion.begin[0], outputRegion.size[0], r.x, volumeDims[0]))
    , ys(readSpan(outputRegion.begin[1], outputRegion.size[1], r.y, volumeDims[1]))
    , zs(readSpan(outputRegion.begin[2], outputRegion.size[2], r.z, volumeDims[2]))
  {
  }

  std::int64_t planeSize() const { return region.size[0] * region.size[1]; }
  /// Clipped window sizes along x and y of every region column and row.
  std::vector<std::int64_t> windowCounts(int axis) const
  {
    const int r = axis == 0 ? radius.x : (axis == 1 ? radius.y : radius.z);
    std::vector<std::int64_t> counts(static_cast<std::size_t>(region.size[axis]));
    for (std::int64_t i = 0; i < region.size[axis]; ++i)
    {
      counts[i] = clippedWindowCount(region.begin[axis] + i, r, dims[axis]);
    }
    return counts;
  }
};

/// Whether the box sums of v (exact integer types) can run in 32 bits: every box sum of the
/// region, whatever the values, lies within int32's range. The running sums then wrap
/// modulo 2^32 (unsigned, so wrapping is defined) and each box sum comes out exact; half
/// the bytes and twice the lanes of 64 bits. True for 16-bit data in boxes of up to 32767
/// (uint16) or 65535 (int16) voxels, R = 15 and 19 in cubes.
template <class T>
bool linearSumsFit32(const BoxGeometry& geometry)
{
  static_assert(MomentTraits<T>::exactInteger, "exact integer sums only");
  const double largest =
    std::max(-double(std::numeric_limits<T>::min()), double(std::numeric_limits<T>::max()));
  double voxels = 1.0;
  const int radii[3] = { geometry.radius.x, geometry.radius.y, geometry.radius.z };
  for (int a = 0; a < 3; ++a)
    voxels *= double(std::min<std::int64_t>(2 * std::int64_t(radii[a]) + 1, geometry.dims[a]));
  return voxels * largest < 2147483648.0;
}

/// Where MomentPlanes reads a row's values: the volume itself. A source gives `Value`,
/// `stride()` and row(y, z, x0, n, scratch): the values x0 ... x0 + n - 1 of row (y, z),
/// stride() apart, which a source that derives them from the volume's (kScratch) writes
/// into scratch, n values.
template <class T>
struct VolumeRows
{
  using Value = T;
  static constexpr bool kScratch = false;
  const TypedVolume<T>& volume;

  std::int64_t stride() const { return this->volume.stride; }
  const T* row(std::int64_t y, std::int64_t z, std::int64_t x0, std::int64_t, T*) const
  {
    return this->volume.row(y, z) + x0 * this->volume.stride;
  }
};

/// Box sums of (v - shift) and, unless told not to (a consumer that needs the mean alone),
/// of (v - shift)^2 for one slice of the region at a time; the sums of v in Lin
/// (std::uint32_t where linearSumsFit32, else the accumulator).
template <class T, class Lin = typename MomentTraits<T>::Accumulator, class Source = VolumeRows<T>>
class MomentPlanes
{
public:
  using Acc = typename MomentTraits<T>::Accumulator;
  // 8-bit and int16 values with 32-bit sums of v: each row's differences of squares
  // a^2 - b^2 fit in int32 (RowDifferences), and their x sums run modulo 2^32 too
  // in the rows where no window can leave int32's range (boxRowDifference).
  static constexpr bool kNarrowSquares =
    std::is_same<Lin, std::uint32_t>::value && kSquaresFitInt32<T>;

  MomentPlanes(const Source& rows, const BoxGeometry& geometry, Acc shift, bool squares)
    : Rows(rows)
    , Geo(geometry)
    , Shift(shift)
    , Squares(squares)
    , Sum(geometry.planeSize())
    , SumSquares(squares ? geometry.planeSize() : 0)
    , Row1(geometry.xs.size() + 1)
    , Row2(squares ? geometry.xs.size() + 1 : 0)
    , Row2Narrow(squares && kNarrowSquares ? geometry.xs.size() + 1 : 0)
    , RingRows(std::min<std::int64_t>(2 * std::int64_t(geometry.radius.y) + 2, geometry.ys.size()))
    , XBox1(RingRows * geometry.region.size[0])
    , XBox2(squares ? RingRows * geometry.region.size[0] : 0)
    , XBox2Narrow(squares && kNarrowSquares ? RingRows * geometry.region.size[0] : 0)
    , SlotNarrow(static_cast<std::size_t>(RingRows), 0)
    , Run1(geometry.region.size[0])
    , Run2(squares ? geometry.region.size[0] : 0)
    , Zeros(geometry.region.size[0], Acc(0))
    , ZerosLin(geometry.region.size[0], Lin(0))
    , ZerosNarrow(kNarrowSquares ? geometry.region.size[0] : 0, 0)
    , Entering(Source::kScratch ? geometry.xs.size() : 0)
    , Leaving(Source::kScratch ? geometry.xs.size() : 0)
  {
  }

  /// Sets the planes to the box sums of output slice z (window clipped to the volume).
  void startAt(std::int64_t z)
  {
    std::fill(this->Sum.begin(), this->Sum.end(), Lin(0));
    std::fill(this->SumSquares.begin(), this->SumSquares.end(), Acc(0));
    const std::int64_t lo = std::max<std::int64_t>(0, z - this->Geo.radius.z);
    const std::int64_t hi = std::min<std::int64_t>(this->Geo.dims[2] - 1, z + this->Geo.radius.z);
    for (std::int64_t s = lo; s <= hi; ++s)
    {
      this->addSliceDifference(s, -1);
    }
  }

  /// Moves the planes from output slice z to z + 1.
  void advanceFrom(std::int64_t z)
  {
    const std::int64_t entering = z + this->Geo.radius.z + 1;
    const std::int64_t leaving = z - this->Geo.radius.z;
    this->addSliceDifference(
      entering < this->Geo.dims[2] ? entering : -1, leaving >= 0 ? leaving : -1);
  }

  const Lin* sum() const { return this->Sum.data(); }
  /// Null when the squares were not asked for.
  const Acc* sumSquares() const { return this->Squares ? this->SumSquares.data() : nullptr; }

private:
  /// Adds the 2-D box sums of slice `entering` and subtracts those of `leaving` (-1: none):
  /// plane[y] += the sum of the x-box rows in y's clipped window, by running sums over the
  /// rows. Each x-box row is formed just before it enters the window, into a ring of the
  /// 2 r_y + 2 rows that a window and its next entering row span, so the rows stay in cache.
  void addSliceDifference(std::int64_t entering, std::int64_t leaving)
  {
    if (entering < 0 && leaving < 0)
    {
      return;
    }
    const std::int64_t nx = this->Geo.region.size[0];
    const std::int64_t r = this->Geo.radius.y;
    const std::int64_t ny = this->Geo.dims[1];
    const std::int64_t y0 = this->Geo.region.begin[1];
    const Acc* zeros = this->Zeros.data();
    std::fill(this->Run1.begin(), this->Run1.end(), Lin(0));
    const Lin* zerosLin = this->ZerosLin.data();
    std::fill(this->Run2.begin(), this->Run2.end(), Acc(0));
    const auto slide = [&](std::int64_t row, std::int64_t in, std::int64_t out)
    {
      Lin* plane1 = row < 0 ? nullptr : this->Sum.data() + row * nx;
      Acc* plane2 = row < 0 ? nullptr : this->SumSquares.data() + row * nx;
      runRows<SlideColumns<Lin>>(this->Simd, plane1, this->Run1.data(),
        in < 0 ? zerosLin : this->xbox1(in), out < 0 ? zerosLin : this->xbox1(out), nx);
      if (this->Squares)
        this->slideSquares(plane2, in, out);
    };
    for (std::int64_t y = std::max<std::int64_t>(0, y0 - r); y <= std::min(ny - 1, y0 + r); ++y)
    {
      this->boxRowDifference(y, entering, leaving);
      slide(-1, y, -1);
    }
    for (std::int64_t row = 0; row < this->Geo.region.size[1]; ++row)
    {
      // The last row has no next one: its window's entering row may lie past the rows read.
      const std::int64_t y = y0 + row;
      const bool last = row + 1 == this->Geo.region.size[1];
      const std::int64_t in = !last && y + r + 1 < ny ? y + r + 1 : -1;
      const std::int64_t out = !last && y - r >= 0 ? y - r : -1;
      if (in >= 0)
        this->boxRowDifference(in, entering, leaving);
      slide(row, in, out);
    }
  }

  std::int64_t slot(std::int64_t y) const { return (y - this->Geo.ys.lo) % this->RingRows; }
  Lin* xbox1(std::int64_t y)
  {
    return this->XBox1.data() + this->slot(y) * this->Geo.region.size[0];
  }
  Acc* xbox2(std::int64_t y)
  {
    return this->XBox2.data() + this->slot(y) * this->Geo.region.size[0];
  }
  /// Row y's x-box sums of squares where each fits in int32 (narrow: half the bytes in
  /// the ring, so that on CT-like data the ring stays in the first-level cache).
  std::int32_t* xbox2Narrow(std::int64_t y)
  {
    return this->XBox2Narrow.data() + this->slot(y) * this->Geo.region.size[0];
  }

  /// The y pass of the squares: Run2 moves on by row `in` and `out` (-1: none), each read
  /// from whichever ring holds it, after plane2 (when not null) has taken it.
  void slideSquares(Acc* plane2, std::int64_t in, std::int64_t out)
  {
    const std::int64_t nx = this->Geo.region.size[0];
    Acc* run = this->Run2.data();
    if constexpr (kNarrowSquares)
    {
      // A missing row reads as a narrow row of zeros.
      const bool narrowIn = in < 0 || this->SlotNarrow[this->slot(in)];
      const bool narrowOut = out < 0 || this->SlotNarrow[this->slot(out)];
      const std::int32_t* in32 = in < 0 ? this->ZerosNarrow.data() : this->xbox2Narrow(in);
      const std::int32_t* out32 = out < 0 ? this->ZerosNarrow.data() : this->xbox2Narrow(out);
      if (narrowIn && narrowOut)
        return runRows<SlideColumns<Acc, std::int32_t, std::int32_t>>(
          this->Simd, plane2, run, in32, out32, nx);
      if (narrowIn)
        return runRows<SlideColumns<Acc, std::int32_t, Acc>>(
          this->Simd, plane2, run, in32, this->xbox2(out), nx);
      if (narrowOut)
        return runRows<SlideColumns<Acc, Acc, std::int32_t>>(
          this->Simd, plane2, run, this->xbox2(in), out32, nx);
    }
    const Acc* zeros = this->Zeros.data();
    runRows<SlideColumns<Acc>>(this->Simd, plane2, run, in < 0 ? zeros : this->xbox2(in),
      out < 0 ? zeros : this->xbox2(out), nx);
  }

  /// x box sums of one row of (entering - leaving), stored in the ring at xbox1(y), xbox2(y).
  void boxRowDifference(std::int64_t y, std::int64_t entering, std::int64_t leaving)
  {
    const std::int64_t span = this->Geo.xs.size();
    const std::int64_t stride = this->Rows.stride();
    const std::int64_t r = this->Geo.radius.x;
    Lin* p1 = this->Row1.data();
    Acc* p2 = this->Row2.data();
    std::uint32_t* q2 = this->Row2Narrow.data();
    const std::int64_t lo = this->Geo.xs.lo;
    const T* in =
      entering >= 0 ? this->Rows.row(y, entering, lo, span, this->Entering.data()) : nullptr;
    const T* out =
      leaving >= 0 ? this->Rows.row(y, leaving, lo, span, this->Leaving.data()) : nullptr;
    // The differences of the two rows (a vector loop), then their prefix sums:
    // p[i] = sum of the first i values.
    p1[0] = 0;
    bool narrowSquares = false; // the squares' prefix sums are q2's, modulo 2^32
    if constexpr (kNarrowSquares)
    {
      if (this->Squares)
      {
        std::int32_t largest = 0;
        runRows<RowDifferences<T, Acc, true, Lin, std::uint32_t>>(
          this->Simd, in, out, stride, span, this->Shift, p1 + 1, q2 + 1, &largest);
        q2[0] = 0;
        // No window (at most 2r + 1 values of the row) sums past int32's range.
        narrowSquares = double(std::min<std::int64_t>(2 * r + 1, span)) * largest < 2147483648.0;
        if (!narrowSquares) // the 64-bit sums below, from the same differences
          for (std::int64_t i = 0; i <= span; ++i)
            p2[i] = static_cast<std::int32_t>(q2[i]);
      }
    }
    if (!(kNarrowSquares && this->Squares))
    {
      if (this->Squares)
      {
        runRows<RowDifferences<T, Acc, true, Lin>>(
          this->Simd, in, out, stride, span, this->Shift, p1 + 1, p2 + 1);
        p2[0] = 0;
      }
      else
        runRows<RowDifferences<T, Acc, false, Lin>>(
          this->Simd, in, out, stride, span, this->Shift, p1 + 1, p2);
    }
    if constexpr (std::is_same<Lin, std::uint32_t>::value)
    {
      // Modulo 2^32, as every box sum below; with the narrow squares' in the same loop.
      runningTotals(p1, narrowSquares ? q2 : nullptr, span + 1, this->Simd);
      if (this->Squares && !narrowSquares)
        runningTotals(p2, nullptr, span + 1, this->Simd);
    }
    else if constexpr (std::is_same<Acc, std::int64_t>::value)
      runningTotals(p1, this->Squares ? p2 : nullptr, span + 1,
        this->Simd); // exact: any order of the additions
    else if constexpr (std::is_same<Lin, std::int64_t>::value)
    {
      runningTotals(p1, nullptr, span + 1, this->Simd); // integer sums of v: exact
      if (this->Squares)
        for (std::int64_t i = 0; i < span; ++i)
          p2[i + 1] += p2[i];
    }
    else
      for (std::int64_t i = 0; i < span; ++i) // double sums: this order on every tier
      {
        p1[i + 1] += p1[i];
        if (this->Squares)
          p2[i + 1] += p2[i];
      }
    if (narrowSquares)
      this->windowSums(p1, q2, y);
    else
      this->windowSums(p1, this->Squares ? p2 : nullptr, y);
  }

  /// The x-box sums of row y from its prefix sums (those of the squares in Acc or, modulo
  /// 2^32, in std::uint32_t; null without the squares) into the ring.
  template <class Sq>
  void windowSums(const Lin* p1, const Sq* p2, std::int64_t y)
  {
    const std::int64_t span = this->Geo.xs.size();
    const std::int64_t nx = this->Geo.region.size[0];
    const std::int64_t r = this->Geo.radius.x;
    const std::int64_t x0 = this->Geo.region.begin[0] - this->Geo.xs.lo; // first output in span
    Lin* box1 = this->xbox1(y);
    // Sums of squares from 32-bit prefix sums (Sq = std::uint32_t) fit in int32: the narrow ring.
    constexpr bool narrow =
      std::is_same<Sq, std::uint32_t>::value && !std::is_same<Acc, std::uint32_t>::value;
    using Box = typename std::conditional<narrow, std::int32_t, Acc>::type;
    Box* box2 = nullptr;
    if (p2)
    {
      if constexpr (narrow)
        box2 = this->xbox2Narrow(y);
      else
        box2 = this->xbox2(y);
      this->SlotNarrow[this->slot(y)] = narrow;
    }
    // Outputs whose window lies inside the span (a vector loop) and the clamped ends.
    const std::int64_t first = std::min(nx, std::max<std::int64_t>(0, r - x0));
    const std::int64_t end = std::max(first, std::min(nx, span - r - x0));
    const auto clamped = [&](std::int64_t i)
    {
      const std::int64_t lo = std::max<std::int64_t>(0, x0 + i - r);
      const std::int64_t hi = std::min<std::int64_t>(span, x0 + i + r + 1);
      box1[i] = p1[hi] - p1[lo];
      if (box2)
        box2[i] = squaresWindow<Box>(p2[hi] - p2[lo]);
    };
    for (std::int64_t i = 0; i < first; ++i)
      clamped(i);
    if (box2)
      runRows<WindowDifferences<Box, true, Lin, Sq>>(
        this->Simd, p1, p2, x0 - r, 2 * r + 1, box1, box2, first, end);
    else
      runRows<WindowDifferences<Box, false, Lin, Sq>>(
        this->Simd, p1, p2, x0 - r, 2 * r + 1, box1, box2, first, end);
    for (std::int64_t i = end; i < nx; ++i)
      clamped(i);
  }

  const Source& Rows;
  const BoxGeometry& Geo;
  Acc Shift;
  bool Squares; // the sums of squares are formed (else their rows are empty)
  std::vector<Lin> Sum;
  std::vector<Acc> SumSquares;
  std::vector<Lin> Row1;
  std::vector<Acc> Row2;
  std::vector<std::uint32_t> Row2Narrow; // kNarrowSquares: the squares' differences, 32-bit
  std::int64_t RingRows;                 // x-box rows kept: a window's and the next entering one
  std::vector<Lin> XBox1;
  std::vector<Acc> XBox2;
  std::vector<std::int32_t> XBox2Narrow; // kNarrowSquares: the rows whose sums fit in int32
  std::vector<char> SlotNarrow;          // per ring slot: its squares are in XBox2Narrow
  std::vector<Lin> Run1;
  std::vector<Acc> Run2;
  std::vector<Acc> Zeros;                // a row outside the volume
  std::vector<Lin> ZerosLin;             // the same for the sums of v
  std::vector<std::int32_t> ZerosNarrow; // and for the narrow squares
  std::vector<T> Entering, Leaving;      // Source::kScratch: the rows it derived
  SimdTier Simd = cpuSimdTier();
};

/// Per-slice view handed to the consumer of the moments: everything needed to turn the
/// sums of slice z into statistics.
template <class T, class Lin = typename MomentTraits<T>::Accumulator>
struct MomentSlice
{
  using Acc = typename MomentTraits<T>::Accumulator;
  std::int64_t z;          // output slice, volume coordinates
  const Lin* sum;          // region plane, x fastest (uint32: the int32 sums' bits)
  const Acc* sumSquares;   // null when not asked for
  double shift;            // add to sum / count to get the mean
  std::int64_t countZ;     // clipped window size along z
  double roundingVariance; // what rounding can fake on a flat box (MomentScale)
};

/// Streams the moment planes of every region slice to consume(slice) on worker threads;
/// each thread takes a contiguous chunk of slices and a consumer of its own, made by
/// makeConsumer(), whose buffers then serve the chunk's slices, not one slice each. The
/// sums of v are in Lin (std::uint32_t only where linearSumsFit32), the sums of squares
/// formed only if `squares`. The values are read from `rows` (VolumeRows: the volume's).
/// Returns false when cancelled.
template <class Lin, class Source, class MakeConsumer>
bool streamMomentsOf(const Source& rows, const BoxGeometry& geometry, const MomentScale& scale,
  bool squares, const Execution& execution, MakeConsumer&& makeConsumer)
{
  using T = typename Source::Value;
  const auto shift = static_cast<typename MomentTraits<T>::Accumulator>(scale.shift);
  const int threads = resolveThreadCount(execution.threads);
  const std::int64_t nz = geometry.region.size[2];
  return parallelFor(nz, threads, threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      MomentPlanes<T, Lin, Source> planes(rows, geometry, shift, squares);
      auto consume = makeConsumer();
      for (std::int64_t k = begin; k < end; ++k)
      {
        const std::int64_t z = geometry.region.begin[2] + k;
        if (k == begin)
        {
          planes.startAt(z);
        }
        else
        {
          planes.advanceFrom(z - 1);
        }
        MomentSlice<T, Lin> slice{ z, planes.sum(), planes.sumSquares(), static_cast<double>(shift),
          clippedWindowCount(z, geometry.radius.z, geometry.dims[2]), scale.roundingVariance };
        consume(slice);
        if (!progress.advance())
        {
          return;
        }
      }
    });
}

/// streamMomentsOf the volume's own values.
template <class T, class Lin, class MakeConsumer>
bool streamMoments(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const MomentScale& scale, bool squares, const Execution& execution, MakeConsumer&& makeConsumer)
{
  return streamMomentsOf<Lin>(VolumeRows<T>{ volume }, geometry, scale, squares, execution,
    std::forward<MakeConsumer>(makeConsumer));
}

} // namespace detail
} // namespace vao
