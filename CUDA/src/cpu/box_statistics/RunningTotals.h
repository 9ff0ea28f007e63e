// Running totals of rows of 64- and 32-bit integers in place, for the box sums' x pass
// (MomentPlanes.h): integer sums are exact (32-bit ones modulo 2^32), so any order of the
// additions gives the same values, and a vector forms several totals at once by a scan
// within the register (shifted adds) plus the total carried from the vector before: eight
// 64-bit totals on AVX-512, four on AVX2, sixteen 32-bit ones on AVX-512, eight on AVX2. The
// serial sum waits one addition per value; the scan, one per vector.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#include <cstdint>

namespace vao
{
namespace detail
{

/// a[i] += a[i - 1] and b[i] += b[i - 1] for i in [1, n): the running totals of both rows
/// (of a alone where b is null).
void runningTotals(std::int64_t* a, std::int64_t* b, std::int64_t n, SimdTier tier);

/// a[i] += a[i - 1] (and b[i] += b[i - 1] unless b is null) for i in [1, n) modulo 2^32:
/// 32-bit sums whose every difference of two totals, a box sum, is exact as an int32
/// (MomentPlanes.h's linearSumsFit32).
void runningTotals(std::uint32_t* a, std::uint32_t* b, std::int64_t n, SimdTier tier);

} // namespace detail
} // namespace vao
