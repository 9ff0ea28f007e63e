// Vectors of doubles on AVX2 (four lanes, namespace avx2) and AVX-512 (eight, namespace
// avx512) behind one set of names, so that the estimators' lane formulas
// (EstimatorLanes-inl.h) are written once and compiled for both: every operation is the
// same IEEE operation per lane in both, so both tiers give the same bits but for the
// vector erf, exp and log, which glibc's libmvec implements per width (within a few ulps),
// and AVX-512's erf, which is the piecewise polynomial of ErfPieces.h.
//
// Why a re-included formula file and not a template over these two sets: GCC inlines a
// target-specific intrinsic only into a function of that target, and a template cannot
// take its target from its parameter.
#pragma once

#include "cpu/simd/CpuDispatch.h"
#include "cpu/simd/ErfPieces.h"

#if VAO_HAVE_AVX2_TARGET && defined(VAO_HAVE_LIBMVEC)
#define VAO_VECTOR_MATH 1 // glibc's vector erf, exp and log (libmvec)
#else
#define VAO_VECTOR_MATH 0
#endif

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>

#include <cstdint>

#if VAO_VECTOR_MATH
// Their x86-64 vector function ABI names.
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4v_erf(__m256d);
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4v_exp(__m256d);
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4v_log(__m256d);
extern "C" __attribute__((target("avx512f"))) __m512d _ZGVeN8v_erf(__m512d);
extern "C" __attribute__((target("avx512f"))) __m512d _ZGVeN8v_exp(__m512d);
extern "C" __attribute__((target("avx512f"))) __m512d _ZGVeN8v_log(__m512d);
#endif

namespace vao
{
namespace detail
{
namespace avx2
{
using D = __m256d;
using I = __m256i;    // 64-bit integers
using Mask = __m256d; // all bits set in the lanes where true
constexpr int kWidth = 4;
#define VAO_LANES VAO_AVX2_HELPER

VAO_LANES D set1(double x)
{
  return _mm256_set1_pd(x);
}
VAO_LANES D zero()
{
  return _mm256_setzero_pd();
}
VAO_LANES D load(const double* p)
{
  return _mm256_loadu_pd(p);
}
VAO_LANES I loadIntegers(const std::int64_t* p)
{
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}
VAO_LANES void store(double* p, D x)
{
  _mm256_storeu_pd(p, x);
}
/// kWidth values from p as doubles (integers of a narrower type converted exactly).
VAO_LANES D loadAsDoubles(const double* p)
{
  return load(p);
}
VAO_LANES D loadAsDoubles(const std::int16_t* p)
{
  return _mm256_cvtepi32_pd(
    _mm_cvtepi16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
}
VAO_LANES D loadAsDoubles(const std::uint16_t* p)
{
  return _mm256_cvtepi32_pd(
    _mm_cvtepu16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
}
VAO_LANES D loadAsDoubles(const std::int32_t* p)
{
  return _mm256_cvtepi32_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}
VAO_LANES void storeFloats(float* p, D x)
{
  _mm_storeu_ps(p, _mm256_cvtpd_ps(x));
}
VAO_LANES D add(D a, D b)
{
  return _mm256_add_pd(a, b);
}
VAO_LANES D sub(D a, D b)
{
  return _mm256_sub_pd(a, b);
}
VAO_LANES D mul(D a, D b)
{
  return _mm256_mul_pd(a, b);
}
VAO_LANES D div(D a, D b)
{
  return _mm256_div_pd(a, b);
}
VAO_LANES D sqrt(D a)
{
  return _mm256_sqrt_pd(a);
}
VAO_LANES D min(D a, D b)
{
  return _mm256_min_pd(a, b);
}
VAO_LANES D max(D a, D b)
{
  return _mm256_max_pd(a, b);
}
VAO_LANES D abs(D a)
{
  return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a);
}
VAO_LANES Mask lessThan(D a, D b)
{
  return _mm256_cmp_pd(a, b, _CMP_LT_OQ);
}
VAO_LANES Mask lessEqual(D a, D b)
{
  return _mm256_cmp_pd(a, b, _CMP_LE_OQ);
}
VAO_LANES Mask greaterThan(D a, D b)
{
  return _mm256_cmp_pd(a, b, _CMP_GT_OQ);
}
VAO_LANES Mask greaterEqual(D a, D b)
{
  return _mm256_cmp_pd(a, b, _CMP_GE_OQ);
}
VAO_LANES Mask either(Mask a, Mask b)
{
  return _mm256_or_pd(a, b);
}
VAO_LANES Mask both(Mask a, Mask b)
{
  return _mm256_and_pd(a, b);
}
VAO_LANES bool all(Mask m)
{
  return _mm256_movemask_pd(m) == 0xF;
}
VAO_LANES bool none(Mask m)
{
  return _mm256_movemask_pd(m) == 0;
}
/// yes where m, else no.
VAO_LANES D select(Mask m, D yes, D no)
{
  return _mm256_blendv_pd(no, yes, m);
}
/// x where m, else 0.
VAO_LANES D onlyWhere(Mask m, D x)
{
  return _mm256_and_pd(m, x);
}
/// a * b + c rounded once (an explicit one: these files are compiled without contraction).
VAO_LANES D fusedMultiplyAdd(D a, D b, D c)
{
  return _mm256_fmadd_pd(a, b, c);
}
VAO_LANES Mask everyLane()
{
  return _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
}
/// a and not b.
VAO_LANES Mask butNot(Mask a, Mask b)
{
  return _mm256_andnot_pd(b, a);
}
/// Not NaN.
VAO_LANES Mask ordered(D a)
{
  return _mm256_cmp_pd(a, a, _CMP_ORD_Q);
}
/// a < b, 64-bit signed.
VAO_LANES Mask lessThan(I a, I b)
{
  return _mm256_castsi256_pd(_mm256_cmpgt_epi64(b, a));
}
VAO_LANES I set1(std::int64_t x)
{
  return _mm256_set1_epi64x(x);
}
/// Integers of magnitude below 2^51 to doubles (exact): added to the bits of 1.5 * 2^52,
/// they are its mantissa.
VAO_LANES D smallIntegersToDouble(I x)
{
  const __m256d magic = _mm256_set1_pd(6755399441055744.0);
  return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(x, _mm256_castpd_si256(magic))), magic);
}
#if VAO_VECTOR_MATH
VAO_LANES D erf(D x)
{
  return _ZGVdN4v_erf(x);
}
VAO_LANES D exp(D x)
{
  return _ZGVdN4v_exp(x);
}
VAO_LANES D log(D x)
{
  return _ZGVdN4v_log(x);
}
#endif
#undef VAO_LANES
} // namespace avx2

namespace avx512
{
using D = __m512d;
using I = __m512i;
using Mask = __mmask8;
constexpr int kWidth = 8;
#define VAO_LANES VAO_AVX512_HELPER

VAO_LANES D set1(double x)
{
  return _mm512_set1_pd(x);
}
VAO_LANES D zero()
{
  return _mm512_setzero_pd();
}
VAO_LANES D load(const double* p)
{
  return _mm512_loadu_pd(p);
}
VAO_LANES I loadIntegers(const std::int64_t* p)
{
  return _mm512_loadu_si512(p);
}
VAO_LANES void store(double* p, D x)
{
  _mm512_storeu_pd(p, x);
}
VAO_LANES D loadAsDoubles(const double* p)
{
  return load(p);
}
VAO_LANES D loadAsDoubles(const std::int16_t* p)
{
  return _mm512_cvtepi32_pd(
    _mm256_cvtepi16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))));
}
VAO_LANES D loadAsDoubles(const std::uint16_t* p)
{
  return _mm512_cvtepi32_pd(
    _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))));
}
VAO_LANES D loadAsDoubles(const std::int32_t* p)
{
  return _mm512_cvtepi32_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)));
}
VAO_LANES void storeFloats(float* p, D x)
{
  _mm256_storeu_ps(p, _mm512_cvtpd_ps(x));
}
VAO_LANES D add(D a, D b)
{
  return _mm512_add_pd(a, b);
}
VAO_LANES D sub(D a, D b)
{
  return _mm512_sub_pd(a, b);
}
VAO_LANES D mul(D a, D b)
{
  return _mm512_mul_pd(a, b);
}
VAO_LANES D div(D a, D b)
{
  return _mm512_div_pd(a, b);
}
VAO_LANES D sqrt(D a)
{
  return _mm512_sqrt_pd(a);
}
VAO_LANES D min(D a, D b)
{
  return _mm512_min_pd(a, b);
}
VAO_LANES D max(D a, D b)
{
  return _mm512_max_pd(a, b);
}
VAO_LANES D abs(D a)
{
  return _mm512_abs_pd(a);
}
VAO_LANES Mask lessThan(D a, D b)
{
  return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ);
}
VAO_LANES Mask lessEqual(D a, D b)
{
  return _mm512_cmp_pd_mask(a, b, _CMP_LE_OQ);
}
VAO_LANES Mask greaterThan(D a, D b)
{
  return _mm512_cmp_pd_mask(a, b, _CMP_GT_OQ);
}
VAO_LANES Mask greaterEqual(D a, D b)
{
  return _mm512_cmp_pd_mask(a, b, _CMP_GE_OQ);
}
VAO_LANES Mask either(Mask a, Mask b)
{
  return static_cast<Mask>(a | b);
}
VAO_LANES Mask both(Mask a, Mask b)
{
  return static_cast<Mask>(a & b);
}
VAO_LANES bool all(Mask m)
{
  return m == 0xFF;
}
VAO_LANES bool none(Mask m)
{
  return m == 0;
}
VAO_LANES D select(Mask m, D yes, D no)
{
  return _mm512_mask_blend_pd(m, no, yes);
}
VAO_LANES D onlyWhere(Mask m, D x)
{
  return _mm512_maskz_mov_pd(m, x);
}
VAO_LANES D fusedMultiplyAdd(D a, D b, D c)
{
  return _mm512_fmadd_pd(a, b, c);
}
VAO_LANES Mask everyLane()
{
  return 0xFF;
}
VAO_LANES Mask butNot(Mask a, Mask b)
{
  return static_cast<Mask>(a & ~b);
}
VAO_LANES Mask ordered(D a)
{
  return _mm512_cmp_pd_mask(a, a, _CMP_ORD_Q);
}
VAO_LANES Mask lessThan(I a, I b)
{
  return _mm512_cmplt_epi64_mask(a, b);
}
VAO_LANES I set1(std::int64_t x)
{
  return _mm512_set1_epi64(x);
}
/// Exact below 2^53 (AVX-512 DQ converts 64-bit integers directly).
VAO_LANES D smallIntegersToDouble(I x)
{
  return _mm512_cvtepi64_pd(x);
}
/// Each lane's entry of a table of the 16 erf pieces (ErfPieces.h), by one permute.
VAO_LANES D ofPiece(const double* table, I piece)
{
  return _mm512_permutex2var_pd(_mm512_load_pd(table), piece, _mm512_load_pd(table + 8));
}
/// erf from ErfPieces.h's 16 polynomials on [0, 6): within 2^-52 of erf (+-1 in doubles
/// past 6), odd, and within 2^-50 relative below 3/8 (erf(0) = 0); cheaper than glibc's
/// vector erf, with a shorter chain of dependent operations. (1 + erf) / 2, the openness,
/// shows an absolute error alone.
VAO_LANES D erf(D x)
{
  const D a = min(abs(x), set1(kErfTop)); // kErfTop for NaN, which is put back below
  const I piece = _mm512_min_epi64(
    _mm512_cvttpd_epi64(mul(a, set1(1.0 / kErfPieceWidth))), set1(std::int64_t(kErfPieces - 1)));
  const D u = sub(a, ofPiece(kErfOrigins, piece));
  // c0 + u t, t = c1 + c2 u + ... by Estrin's scheme: a chain of 5 dependent operations,
  // not Horner's 13, and c0 + u t rounds as Horner's last step (t's rounding shrunk by u).
  static_assert(kErfDegree == 12, "the scheme below is written for degree 12");
  D c[kErfDegree + 1];
#pragma GCC unroll 16
  for (int i = 0; i <= kErfDegree; ++i)
    c[i] = ofPiece(kErfCoefficients[i], piece);
  const D u2 = mul(u, u), u4 = mul(u2, u2), u8 = mul(u4, u4);
  const D t1 =
    fusedMultiplyAdd(fusedMultiplyAdd(c[4], u, c[3]), u2, fusedMultiplyAdd(c[2], u, c[1]));
  const D t5 =
    fusedMultiplyAdd(fusedMultiplyAdd(c[8], u, c[7]), u2, fusedMultiplyAdd(c[6], u, c[5]));
  const D t9 =
    fusedMultiplyAdd(fusedMultiplyAdd(c[12], u, c[11]), u2, fusedMultiplyAdd(c[10], u, c[9]));
  const D t = fusedMultiplyAdd(t9, u8, fusedMultiplyAdd(t5, u4, t1));
  D p = fusedMultiplyAdd(t, u, c[0]);
  p = select(greaterEqual(a, set1(kErfTop)), set1(1.0), p);
  const D signed_ = _mm512_xor_pd(p, _mm512_and_pd(x, set1(-0.0)));
  return select(ordered(x), signed_, x);
}
#if VAO_VECTOR_MATH
VAO_LANES D exp(D x)
{
  return _ZGVeN8v_exp(x);
}
VAO_LANES D log(D x)
{
  return _ZGVeN8v_log(x);
}
#endif
#undef VAO_LANES
} // namespace avx512

} // namespace detail
} // namespace vao
#endif
