// The van Herk / Gil-Werman passes of the GPU pipeline (Pipeline.h): the box minimum and
// maximum along one axis in O(1) per voxel whatever the radius, one thread per block of
// 2 r + 1 voxels of a lane. No CUDA runtime calls.
#pragma once

#include "cuda/common/AxisPasses.h"

namespace vao
{
namespace gpu
{

/// The van Herk block of one thread: its lane and the block [start, end) along the axis.
struct VanHerkBlock
{
  Index lane;
  Index start;
  Index end;

  VAO_HD VanHerkBlock(const AxisPass& pass, Index thread)
    : lane(thread % pass.lanes)
    , start((thread / pass.lanes) * (2 * pass.r + 1))
    , end(lower(start + 2 * pass.r + 1, pass.n))
  {
  }
};

/// The two van Herk steps along one axis, one thread per (lane, block of w = 2r + 1
/// voxels). Suffix (step 1): suffix minimum and maximum of every block into suf*. Output
/// (step 2): the outputs whose window ends in the block, from the block's running prefix
/// and the suffix at the window's start, into out*.
enum class VanHerkStep
{
  Suffix,
  Output,
};

template <class T, VanHerkStep Step>
struct VanHerkKernel
{
  const T* inMin;
  const T* inMax;
  T* sufMin; // written by the suffix step, read by the output step
  T* sufMax;
  T* outMin; // the output step's only
  T* outMax;
  AxisPass pass;

  VAO_HD Index threads() const { return pass.lanes * pass.blocks(); }

  VAO_HD void operator()(Index thread) const
  {
    const VanHerkBlock block(pass, thread);
    if (Step == VanHerkStep::Suffix)
      this->suffix(block.lane, block.start, block.end);
    else
      this->output(block.lane, block.start, block.end);
  }

  VAO_HD void suffix(Index lane, Index start, Index end) const
  {
    Index at = pass.in.at(lane, end - 1);
    T lo = inMin[at], hi = inMax[at];
    sufMin[at] = lo;
    sufMax[at] = hi;
    for (Index i = end - 2; i >= start; --i)
    {
      at = pass.in.at(lane, i);
      lo = lower(lo, inMin[at]);
      hi = greater(hi, inMax[at]);
      sufMin[at] = lo;
      sufMax[at] = hi;
    }
  }

  VAO_HD void output(Index lane, Index start, Index end) const
  {
    T preMin = inMin[pass.in.at(lane, start)], preMax = inMax[pass.in.at(lane, start)];
    Index prefixEnd = start; // the prefix covers [start, prefixEnd]
    // The outputs whose window end hi = min(n - 1, i + r) lies in [start, end): windows
    // clipped at the end of the data end in the last block.
    const Index iFirst = greater(pass.outBegin, start - pass.r);
    const Index iLast =
      lower(pass.outBegin + pass.outCount - 1, end == pass.n ? pass.n - 1 : end - 1 - pass.r);
    for (Index i = iFirst; i <= iLast; ++i)
    {
      const Index hi = lower(pass.n - 1, i + pass.r);
      while (prefixEnd < hi)
      {
        ++prefixEnd;
        const Index at = pass.in.at(lane, prefixEnd);
        preMin = lower(preMin, inMin[at]);
        preMax = greater(preMax, inMax[at]);
      }
      const Index lo = greater(Index(0), i - pass.r);
      T resultMin = preMin, resultMax = preMax; // the window starts the block
      if (lo < start)
      {
        // It spans the previous block's suffix from lo and this block's prefix to hi.
        const Index at = pass.in.at(lane, lo);
        resultMin = lower(sufMin[at], preMin);
        resultMax = greater(sufMax[at], preMax);
      }
      else if (lo > start)
      {
        // Clipped at the end of the data: the suffix of this (last) block from lo.
        const Index at = pass.in.at(lane, lo);
        resultMin = sufMin[at];
        resultMax = sufMax[at];
      }
      const Index to = pass.out.at(lane, i - pass.outBegin);
      outMin[to] = resultMin;
      outMax[to] = resultMax;
    }
  }
};

} // namespace gpu
} // namespace vao
