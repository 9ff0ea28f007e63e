// The one-axis passes of the GPU pipeline (Pipeline.h), written once for the CUDA
// executor and the host emulator: lanes and their layout, running-sum segments, the
// moments' source and the box sums of two channels along one axis. No CUDA runtime calls.
#pragma once

#include "vao/AmbientOcclusion.h"
#include "vao/Estimators.h"

#include <cstdint>

namespace vao
{
namespace gpu
{

using Index = long long;

template <class T>
VAO_HD T lower(T a, T b)
{
  return b < a ? b : a;
}
template <class T>
VAO_HD T greater(T a, T b)
{
  return a < b ? b : a;
}

/// Element (lane, i) of an array seen as lanes along one axis: lanes run over an inner
/// dimension (contiguous) and an outer one; i steps along the axis.
struct LaneLayout
{
  Index inner;       // lanes along the contiguous dimension
  Index outerStride; // elements between consecutive outer lanes
  Index step;        // elements between consecutive voxels along the axis

  VAO_HD Index at(Index lane, Index i) const
  {
    return (lane / inner) * outerStride + lane % inner + i * step;
  }
};

/// One sliding-window pass along an axis: n input voxels per lane, outCount outputs for
/// positions outBegin.., windows of half-width r clipped to [0, n).
struct AxisPass
{
  Index lanes;
  Index n;
  Index r;
  Index outBegin;
  Index outCount;
  LaneLayout in;
  LaneLayout out;

  VAO_HD Index blocks() const { return (n + 2 * r) / (2 * r + 1); } // van Herk blocks per lane
};

/// Outputs one thread of a running-sum pass computes: its initial window costs 2r + 1
/// additions, spread over at least as many outputs, so the cost per voxel stays O(1).
VAO_HD Index segmentLength(Index r)
{
  return 2 * (2 * r + 1) > 32 ? 2 * (2 * r + 1) : 32;
}

VAO_HD Index segmentsOf(Index count, Index segment)
{
  return (count + segment - 1) / segment;
}

/// Value of voxel i of a lane as the accumulator sees it: raw input (first pass, shifted,
/// squared for the second moment) or the previous pass's two sums.
template <class TIn, class Acc, bool FromInput>
struct MomentSource
{
  const TIn* first;
  const TIn* second; // unused when FromInput: both moments come from `first`
  Acc shift;

  VAO_HD void load(Index index, Acc& v1, Acc& v2) const
  {
    if (FromInput)
    {
      const Acc v = static_cast<Acc>(first[index]) - shift;
      v1 = v;
      v2 = v * v;
    }
    else
    {
      v1 = static_cast<Acc>(first[index]);
      v2 = static_cast<Acc>(second[index]);
    }
  }
};

/// Box sums of two channels along one axis (the moments, or Histogram CDF's indicators):
/// one thread per (lane, segment of outputs), a running window moved by one addition and
/// one subtraction per output. Source::load(index, v1, v2) gives a voxel's two values.
template <class Source, class Acc>
struct SumKernel
{
  Source source;
  Acc* out1;
  Acc* out2;
  AxisPass pass;
  Index segment;

  VAO_HD Index threads() const { return pass.lanes * segmentsOf(pass.outCount, segment); }

  VAO_HD void operator()(Index thread) const
  {
    const Index lane = thread % pass.lanes; // adjacent threads: adjacent lanes (coalesced)
    const Index first = (thread / pass.lanes) * segment;
    const Index last = lower(first + segment, pass.outCount);
    const Index i0 = pass.outBegin + first;
    const Index lo = greater(Index(0), i0 - pass.r), hi = lower(pass.n - 1, i0 + pass.r);
    Acc s1 = 0, s2 = 0, v1, v2;
    for (Index j = lo; j <= hi; ++j)
    {
      source.load(pass.in.at(lane, j), v1, v2);
      s1 += v1;
      s2 += v2;
    }
    for (Index o = first; o < last; ++o)
    {
      const Index at = pass.out.at(lane, o);
      out1[at] = s1;
      out2[at] = s2;
      const Index i = pass.outBegin + o + 1; // the next output's window
      if (i + pass.r <= pass.n - 1)
      {
        source.load(pass.in.at(lane, i + pass.r), v1, v2);
        s1 += v1;
        s2 += v2;
      }
      if (i - pass.r - 1 >= 0)
      {
        source.load(pass.in.at(lane, i - pass.r - 1), v1, v2);
        s1 -= v1;
        s2 -= v2;
      }
    }
  }
};

template <class TIn, class Acc, bool FromInput>
using MomentKernel = SumKernel<MomentSource<TIn, Acc, FromInput>, Acc>;

} // namespace gpu
} // namespace vao
