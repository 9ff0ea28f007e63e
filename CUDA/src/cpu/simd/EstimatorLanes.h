// The estimators' lane formulas and row loops (EstimatorLanes-inl.h) for AVX2
// (detail::avx2) and AVX-512 (detail::avx512): the volume's rows (EstimatorRows.cxx,
// MomentRows.cxx) and the surface lanes (SurfaceLanes.h) use them.
#pragma once

#include "cpu/simd/DoubleLanes.h"

#include "vao/Estimators.h"

namespace vao
{
namespace detail
{
#define VAO_TIER_FILE "cpu/simd/EstimatorLanes-inl.h"
#include "cpu/simd/ForEachTier.h"
} // namespace detail
} // namespace vao
