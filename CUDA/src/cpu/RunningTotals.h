// Running totals of rows of 64-bit integers in place, for the box sums' x pass
// (MomentPlanes.h): integer sums are exact, so any order of the additions gives the same
// values, and AVX-512 forms eight at a time by a scan within the register (three shifted
// adds) plus the total carried from the previous eight.
#pragma once

#include "CpuDispatch.h"

#include <cstdint>

namespace vao
{
namespace detail
{

/// a[i] += a[i - 1] and b[i] += b[i - 1] for i in [1, n): the running totals of both rows
/// (of a alone where b is null).
void runningTotals(std::int64_t* a, std::int64_t* b, std::int64_t n, SimdTier tier);

/// a[i] += a[i - 1] for i in [1, n) modulo 2^32: 32-bit sums whose every difference of two
/// totals, a box sum, is exact as an int32 (MomentPlanes.h's linearSumsFit32).
void runningTotals(std::uint32_t* a, std::int64_t n);

} // namespace detail
} // namespace vao
