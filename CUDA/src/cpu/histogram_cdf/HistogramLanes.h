// The lane loops of Histogram CDF on the CPU (HistogramChannels.cxx). A pixel's histogram
// is a vector of `lanes` small unsigned counts held cumulatively: lane c counts the voxels
// of bin c or below, so that adding a voxel adds a row of a mask table and the count below
// a bin is one lane. The loops are structs whose run() runRows compiles for AVX2 as well
// (CpuDispatch.h); `Fixed` is the lane count when it is known at compile time (the
// default 64 bins), 0 when it is read at run time.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#include <cstdint>
#include <type_traits>

namespace vao
{
namespace detail
{

/// The z window moves one slice at one row of pixels: each pixel adds the cumulative mask
/// of the entering voxel's bin and subtracts the leaving one's (`in` or `out` null: a
/// slice outside the volume, as the empty bin `bins`). A pixel whose two voxels share a
/// bin adds and subtracts the same row: no branch, which noisy data would mispredict.
/// Counts wrap modulo the lanes' width, which holds the window's 2 Rz + 1.
template <class W, int Fixed, class B>
struct MoveRow
{
  static VAO_ALWAYS_INLINE void run(const B* __restrict in, const B* __restrict out,
    std::int64_t width, W* __restrict window, const W* __restrict cumulativeMasks, int runtimeLanes,
    int bins)
  {
    const int lanes = Fixed ? Fixed : runtimeLanes;
    for (std::int64_t x = 0; x < width; ++x)
    {
      const int added = in ? in[x] : bins;
      const int removed = out ? out[x] : bins;
      const W* __restrict plus = cumulativeMasks + std::int64_t(added) * lanes;
      const W* __restrict minus = cumulativeMasks + std::int64_t(removed) * lanes;
      W* __restrict pixel = window + x * lanes;
      for (int c = 0; c < lanes; ++c)
        pixel[c] = static_cast<W>(pixel[c] + plus[c] - minus[c]);
    }
  }
};

/// The lowest and highest of a row of n bins.
template <class B>
struct BinRange
{
  static VAO_ALWAYS_INLINE void run(
    const B* __restrict bins, std::int64_t n, B* __restrict lowest, B* __restrict highest)
  {
    B low = bins[0], high = bins[0];
    for (std::int64_t x = 1; x < n; ++x)
    {
      low = bins[x] < low ? bins[x] : low;
      high = bins[x] > high ? bins[x] : high;
    }
    *lowest = low;
    *highest = high;
  }
};

/// columns += entering - leaving over n lanes: the y window's sums move one row down. The
/// difference is taken in the window's width and sign-extended (one widening instead of
/// two), which holds while a window count fits W's signed range (narrowWindow).
template <class L, class W>
struct SlideRows
{
  static VAO_ALWAYS_INLINE void run(L* __restrict columns, const W* __restrict entering,
    const W* __restrict leaving, std::int64_t n)
  {
    using Signed = typename std::make_signed<W>::type;
    for (std::int64_t c = 0; c < n; ++c)
      columns[c] = static_cast<L>(
        columns[c] + static_cast<L>(static_cast<Signed>(static_cast<W>(entering[c] - leaving[c]))));
  }
};

/// The x window over one row of `columns` (width pixels, each the y and z window's
/// cumulative counts), for the outputs from pixel `first`, `count` of them, half-width r:
/// a running histogram plus the pixel entering minus the one leaving. Output i takes from
/// its histogram the count below its bin upper[i] and the count in that bin: below[i] =
/// h[u - 1] (0 for u = 0), at[i] = h[u] - below[i] (0 for u = bins). `histograms` holds
/// `count` histograms (kLag for a known lane count). VectorBytes: the target's vector
/// width (runRowsOfWidth).
template <class L, int Fixed, int VectorBytes>
struct RowQuery
{
  /// Outputs between a histogram's store and the reading of its two lanes: a lane read
  /// back from the vector just stored would wait for the store.
  static constexpr int kLag = 8;

  static VAO_ALWAYS_INLINE void run(const L* __restrict columns, std::int64_t width,
    std::int64_t first, std::int64_t count, std::int64_t r, int runtimeLanes,
    const int* __restrict upper, int bins, L* histograms, std::uint32_t* __restrict below,
    std::uint32_t* __restrict at)
  {
    const std::int64_t lo = first - r > 0 ? first - r : 0;
    const std::int64_t hi = first + r < width - 1 ? first + r : width - 1;
    if constexpr (Fixed > 0)
    {
      (void)runtimeLanes;
      runningRegisters(columns, width, first, count, r, lo, hi, upper, bins, histograms, below, at);
      return;
    }
    const int lanes = runtimeLanes;
    // Each output starts from the one stored before it.
    for (int c = 0; c < lanes; ++c)
      histograms[c] = 0;
    for (std::int64_t x = lo; x <= hi; ++x)
      for (int c = 0; c < lanes; ++c)
        histograms[c] = static_cast<L>(histograms[c] + columns[x * lanes + c]);
    for (std::int64_t i = 1; i < count; ++i)
    {
      const std::int64_t entering = first + i + r, leaving = first + i - r - 1;
      L* next = histograms + i * lanes;
      for (int c = 0; c < lanes; ++c)
        next[c] = histograms[(i - 1) * lanes + c];
      if (entering < width)
        for (int c = 0; c < lanes; ++c)
          next[c] = static_cast<L>(next[c] + columns[entering * lanes + c]);
      if (leaving >= 0)
        for (int c = 0; c < lanes; ++c)
          next[c] = static_cast<L>(next[c] - columns[leaving * lanes + c]);
    }
    for (std::int64_t i = 0; i < count; ++i)
      take(histograms + i * lanes, upper[i], bins, below[i], at[i]);
  }

  /// The counts below and in bin u of a stored histogram.
  static VAO_ALWAYS_INLINE void take(
    const L* __restrict hist, int u, int bins, std::uint32_t& below, std::uint32_t& at)
  {
    const std::uint32_t under = u > 0 ? hist[u - 1] : 0;
    below = under;
    at = u < bins ? static_cast<std::uint32_t>(static_cast<L>(hist[u] - under)) : 0;
  }

  /// The running histogram of a known lane count in vector registers (GCC's and Clang's
  /// vector types of the target's width), stored per output in a ring of kLag histograms
  /// (which stays in the L1 cache) and read kLag - 1 outputs later: a value read back from
  /// memory would wait for its own store on every output.
  static VAO_ALWAYS_INLINE void runningRegisters(const L* __restrict columns, std::int64_t width,
    std::int64_t first, std::int64_t count, std::int64_t r, std::int64_t lo, std::int64_t hi,
    const int* __restrict upper, int bins, L* __restrict ring, std::uint32_t* __restrict below,
    std::uint32_t* __restrict at)
  {
    typedef L Vector __attribute__((vector_size(VectorBytes)));
    // Memory as unaligned vectors free to alias the lanes: loads and stores by assignment,
    // so that no address of a register vector is taken (which keeps it on the stack).
    typedef L Memory __attribute__((vector_size(VectorBytes), aligned(alignof(L)), may_alias));
    constexpr int kPerVector = VectorBytes / sizeof(L);
    constexpr int kVectors = Fixed / kPerVector;
    static_assert(Fixed % kPerVector == 0, "whole vectors of lanes");
    const Memory* __restrict pixels = reinterpret_cast<const Memory*>(columns);
    Memory* __restrict stored = reinterpret_cast<Memory*>(ring);
    Vector h[kVectors] = {};
    for (std::int64_t x = lo; x <= hi; ++x)
      for (int k = 0; k < kVectors; ++k)
        h[k] += pixels[x * kVectors + k];
    for (std::int64_t i = 0; i < count; ++i)
    {
      if (i > 0)
      {
        const std::int64_t entering = first + i + r, leaving = first + i - r - 1;
        if (entering < width)
          for (int k = 0; k < kVectors; ++k)
            h[k] += pixels[entering * kVectors + k];
        if (leaving >= 0)
          for (int k = 0; k < kVectors; ++k)
            h[k] -= pixels[leaving * kVectors + k];
      }
      const std::int64_t slot = i % kLag;
      for (int k = 0; k < kVectors; ++k)
        stored[slot * kVectors + k] = h[k];
      const std::int64_t j = i - (kLag - 1); // the output whose lanes are read now
      if (j >= 0)
        take(ring + (j % kLag) * Fixed, upper[j], bins, below[j], at[j]);
    }
    for (std::int64_t j = count > kLag - 1 ? count - (kLag - 1) : 0; j < count; ++j)
      take(ring + (j % kLag) * Fixed, upper[j], bins, below[j], at[j]);
  }
};

/// q[i] = the value of voxel i of a row, upper[i] = its bin (kept from when its slice
/// entered the window).
template <class T, class B>
struct VoxelQueries
{
  static VAO_ALWAYS_INLINE void run(const T* __restrict values, std::int64_t stride,
    const B* __restrict bins, std::int64_t count, double* __restrict q, int* __restrict upper)
  {
    if (stride == 1)
      for (std::int64_t i = 0; i < count; ++i)
      {
        q[i] = static_cast<double>(values[i]);
        upper[i] = bins[i];
      }
    else
      for (std::int64_t i = 0; i < count; ++i)
      {
        q[i] = static_cast<double>(values[i * stride]);
        upper[i] = bins[i];
      }
  }
};

/// The openness of `count` output voxels from their queries q, bins upper, box counts and
/// the counts below and in their bins: opennessHistogramCdfAt's formula with its branches
/// as selections, so that the row is a vector loop (three divisions per voxel).
/// `lowerEnd[u]` and `upperEnd[u]` are t_(u-1) and t_u for u in [0, n] (the nearest
/// threshold where one is missing). Compiled without fused multiply-adds, as the formula.
struct CdfOpenness
{
  static VAO_ALWAYS_INLINE void run(const double* __restrict q, const int* __restrict upper,
    const double* __restrict boxCounts, const std::uint32_t* __restrict below,
    const std::uint32_t* __restrict at, const double* __restrict lowerEnd,
    const double* __restrict upperEnd, double first, double last, int n, std::int64_t count,
    float* __restrict openness)
  {
    for (std::int64_t i = 0; i < count; ++i)
    {
      const int u = upper[i];
      const double under = static_cast<double>(below[i]);
      const double fUpper = (under + static_cast<double>(at[i])) / boxCounts[i];
      const double fLower = under / boxCounts[i];
      const double tLower = lowerEnd[u], tUpper = upperEnd[u];
      const double a = (q[i] - tLower) / (tUpper - tLower);
      const double line = fLower + a * (fUpper - fLower);
      const double low = line < 0.0 ? 0.0 : line; // clamp01, as selections
      const double between = low > 1.0 ? 1.0 : low;
      const double f = q[i] == tUpper ? fUpper : between;
      const bool top = (u >= n - 1) & (q[i] >= last);
      const double o = top ? 1.0 : f;
      openness[i] = static_cast<float>(q[i] < first ? 0.0 : o);
    }
  }
};

} // namespace detail
} // namespace vao
