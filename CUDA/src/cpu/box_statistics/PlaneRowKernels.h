// The vector row kernels of the moment planes (MomentPlanes.h): the differences of the
// rows entering and leaving the z window, the x windows of their prefix sums, and the
// running column sums of the y pass. Each is a struct whose run() runRows compiles for
// every SIMD tier (CpuDispatch.h).
#pragma once

#include "VolumeAccess.h"
#include "cpu/simd/CpuDispatch.h"

#include <cstdint>
#include <type_traits>

namespace vao
{
namespace detail
{

/// One row of the y pass: plane += run (when plane is not null), then the running column
/// sums move on: run = (run + entering) - leaving, in that order (the rounding of double
/// sums is that of the scalar code it replaced), in one loop that loads run once. The
/// x-box rows entering and leaving may be narrower integers (int32 sums of squares,
/// widened here). Compiled for AVX2 too (CpuDispatch.h).
template <class Acc, class In = Acc, class Out = Acc>
struct SlideColumns
{
  static VAO_ALWAYS_INLINE void run(Acc* __restrict plane, Acc* __restrict run,
    const In* __restrict entering, const Out* __restrict leaving, std::int64_t n)
  {
    if (plane)
      for (std::int64_t i = 0; i < n; ++i)
      {
        const Acc r = run[i];
        plane[i] += r;
        run[i] = (r + static_cast<Acc>(entering[i])) - static_cast<Acc>(leaving[i]);
      }
    else
      for (std::int64_t i = 0; i < n; ++i)
        run[i] = (run[i] + static_cast<Acc>(entering[i])) - static_cast<Acc>(leaving[i]);
  }
};

/// Values whose squares, and the differences of two squares, fit in int32: 8-bit and int16
/// (whose 32-bit products vectorise where 64-bit ones do not on AVX2).
template <class T>
constexpr bool kSquaresFitInt32 =
  std::is_integral<T>::value && (sizeof(T) == 1 || (sizeof(T) == 2 && std::is_signed<T>::value));

/// d1 = a - b (in Lin, modulo 2^32 for std::uint32_t) and, with Squares, d2 = a^2 - b^2,
/// with a, b the values of rows `in` and `out` less the shift (0 for a missing row). d2 is
/// in Sq: Acc, or for 8-bit and int16 values, whose squares' differences fit in int32,
/// std::uint32_t holding those int32 bits, with *largest the greatest |d2| (exact in any
/// order): boxRowDifference then sums them modulo 2^32 where no window's sum can leave
/// int32's range. Compiled for AVX2 too.
template <class T, class Acc, bool Squares = true, class Lin = Acc, class Sq = Acc>
struct RowDifferences
{
  static VAO_ALWAYS_INLINE void run(const T* __restrict in, const T* __restrict out,
    std::int64_t stride, std::int64_t n, Acc shift, Lin* __restrict d1, Sq* __restrict d2,
    std::int32_t* largest = nullptr)
  {
    // Integer sums of v alone for a type whose accumulator is double (int32 fixed-point
    // opacities): the differences in those integers, exact and vectorised.
    constexpr bool integerSums =
      !Squares && std::is_integral<Lin>::value && !std::is_integral<Acc>::value;
    using Wide = typename std::conditional<integerSums, Lin, Acc>::type;
    using Product = typename std::conditional<kSquaresFitInt32<T>, std::int32_t, Wide>::type;
    constexpr bool narrowSquares = Squares && !std::is_same<Sq, Acc>::value;
    static_assert(!narrowSquares || std::is_same<Product, std::int32_t>::value,
      "32-bit squares of 8- and 16-bit values");
    const auto s = static_cast<Product>(shift);
    std::int32_t most = 0;
    for (std::int64_t i = 0; i < n; ++i)
    {
      const Product a = in ? static_cast<Product>(in[i * stride]) - s : Product(0);
      const Product b = out ? static_cast<Product>(out[i * stride]) - s : Product(0);
      d1[i] = static_cast<Lin>(a - b);
      if constexpr (Squares)
      {
        const Product d = a * a - b * b; // |d| <= 2^30 where narrowSquares
        d2[i] = static_cast<Sq>(d);
        if constexpr (narrowSquares)
        {
          const std::int32_t magnitude = d < 0 ? -d : d;
          most = magnitude > most ? magnitude : most;
        }
      }
    }
    if constexpr (narrowSquares)
      *largest = most;
  }
};

/// A window's sum of squares from the difference of two prefix sums: as it is in Acc, or
/// the bits of an int32 sum modulo 2^32 (WindowDifferences).
template <class Acc, class Sq>
VAO_ALWAYS_INLINE Acc squaresWindow(Sq difference)
{
  if constexpr (std::is_same<Sq, std::uint32_t>::value && !std::is_same<Acc, std::uint32_t>::value)
    return static_cast<Acc>(static_cast<std::int32_t>(difference));
  else
    return difference;
}

/// box[i] = p[i + offset + width] - p[i + offset] for i in [begin, end), for both prefix
/// rows (the first, in Lin, alone without Squares). The second's prefix sums are in Sq:
/// Acc, or std::uint32_t modulo 2^32 where every window's sum fits in int32, whose
/// differences are then those sums' bits. Compiled for AVX2 too.
template <class Acc, bool Squares = true, class Lin = Acc, class Sq = Acc>
struct WindowDifferences
{
  static VAO_ALWAYS_INLINE void run(const Lin* __restrict p1, const Sq* __restrict p2,
    std::int64_t offset, std::int64_t width, Lin* __restrict box1, Acc* __restrict box2,
    std::int64_t begin, std::int64_t end)
  {
    for (std::int64_t i = begin; i < end; ++i)
    {
      box1[i] = p1[i + offset + width] - p1[i + offset];
      if constexpr (Squares)
        box2[i] = squaresWindow<Acc>(p2[i + offset + width] - p2[i + offset]);
    }
  }
};

} // namespace detail
} // namespace vao
