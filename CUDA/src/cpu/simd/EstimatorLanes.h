// The estimators' lane formulas and row loops (EstimatorLanes-inl.h) for AVX2
// (detail::avx2) and AVX-512 (detail::avx512): the volume's rows (EstimatorRows.cxx,
// MomentRows.cxx) and the surface lanes (SurfaceLanes.h) use them.
#pragma once

#include "cpu/simd/DoubleLanes.h"

#include "vao/Estimators.h"

#if VAO_HAVE_AVX2_TARGET
namespace vao
{
namespace detail
{
namespace avx2
{
#define VAO_LANES VAO_AVX2_HELPER
#define VAO_LANES_ENTRY VAO_AVX2_INLINE
#include "cpu/simd/EstimatorLanes-inl.h"
#undef VAO_LANES
#undef VAO_LANES_ENTRY
} // namespace avx2

namespace avx512
{
#define VAO_LANES VAO_AVX512_HELPER
#define VAO_LANES_ENTRY VAO_AVX512_INLINE
#include "cpu/simd/EstimatorLanes-inl.h"
#undef VAO_LANES
#undef VAO_LANES_ENTRY
} // namespace avx512
} // namespace detail
} // namespace vao
#endif
