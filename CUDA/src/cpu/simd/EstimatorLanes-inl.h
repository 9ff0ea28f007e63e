// The estimators of Estimators.h on a vector of doubles (DoubleLanes.h), written once and
// included by EstimatorLanes.h into the avx2 and the avx512 namespace, whose D, Mask and
// operations it uses, with VAO_LANES the namespace's inline target. Both branches of a
// formula are formed and one is kept by a mask. Files that use these are compiled without
// fused multiply-adds (-ffp-contract=off), so each lane rounds as the scalar formula does.
// No include guard: included once per namespace.

/// isFlatVariance: true in the lanes whose box is flat.
VAO_LANES Mask flatMask(D variance, D roundingVariance)
{
  return lessEqual(variance, roundingVariance);
}

/// flatOpennessWithin: 1 where q >= mean - max(roundingSpread, kFlatSpread |mean|).
VAO_LANES D flatOpenness(D q, D mean, D roundingSpread)
{
  const D spread = max(roundingSpread, mul(set1(kFlatSpread), abs(mean)));
  return onlyWhere(greaterEqual(q, sub(mean, spread)), set1(1.0));
}

/// opennessChebyshevWithin (the bound's 0/0 on a flat box is not kept).
VAO_LANES D chebyshevOpenness(D q, D mean, D variance, D roundingVariance, D roundingSpread)
{
  const D one = set1(1.0);
  const D d = sub(q, mean);
  const D share = div(variance, add(variance, mul(d, d)));
  const D bound = onlyWhere(greaterThan(d, zero()), min(max(sub(one, share), zero()), one));
  return select(flatMask(variance, roundingVariance), flatOpenness(q, mean, roundingSpread), bound);
}

#if VAO_VECTOR_MATH
/// opennessGaussianCdf with the exact erf. Flat lanes take a variance of 1 into the erf
/// (their 0 would give it infinities or NaN, and libmvec a slow path) and their flat
/// answer after it.
VAO_LANES D gaussianCdf(D q, D mean, D variance, D roundingVariance, D roundingSpread)
{
  const D one = set1(1.0);
  const Mask flat = flatMask(variance, roundingVariance);
  const D z = div(sub(q, mean), sqrt(mul(set1(2.0), select(flat, one, variance))));
  // Beyond |z| = 6 erf is +-1 in doubles (1 - erf(6) ~ 2e-17 is under half an ulp of 1), so
  // the openness is 1 or 0: groups of only such lanes and flat ones skip the erf (most of a
  // volume with smooth regions).
  const Mask saturated = greaterThan(abs(z), set1(6.0));
  D open;
  if (all(either(saturated, flat)))
    open = onlyWhere(greaterThan(z, zero()), one);
  else
    open = min(max(mul(set1(0.5), add(one, erf(z))), zero()), one);
  return select(flat, flatOpenness(q, mean, roundingSpread), open);
}

/// opennessCdfReconstruction: t^beta, its cases (flat box, t at or past either end, the
/// mean at the maximum) by masks in the scalar form's order of precedence. The lanes of
/// those cases take t = 1/2 and beta = 1 into the power; groups of only such lanes skip it.
/// The power is exp(beta log t), half the time of libmvec's pow: with 0 < t < 1 and
/// beta >= 0 its extra rounding is about |beta log t| ulps of a double, below 2e-14
/// relative wherever the float32 openness is not 0 (there beta log t > -104), so the
/// float32 is pow's but within that of a rounding boundary.
VAO_LANES D cdfReconstruction(D q, D mean, D minimum, D maximum)
{
  const D one = set1(1.0);
  const Mask flat = lessEqual(maximum, minimum);
  const D flatOpen = onlyWhere(greaterEqual(q, minimum), one);
  const D t = div(sub(q, minimum), select(flat, one, sub(maximum, minimum)));
  const Mask atTop = greaterEqual(t, one);
  const Mask atBottom = lessEqual(t, zero());
  const D m = min(max(mean, minimum), maximum);
  const Mask meanAtMaximum = greaterEqual(m, maximum);
  const Mask decided = either(either(flat, atTop), either(atBottom, meanAtMaximum));
  // Every decided lane but t >= 1 (and a flat box's, which comes last) is 0.
  D open = onlyWhere(atTop, one);
  if (!all(decided))
  {
    const D beta = div(sub(m, minimum), select(decided, one, sub(maximum, m)));
    const D power = exp(mul(select(decided, one, beta), log(select(decided, set1(0.5), t))));
    open = select(decided, open, power);
  }
  return select(flat, flatOpen, open);
}
#endif

/// The openness of a row of neighbourhoods (EstimatorRows.h's NeighbourhoodRow) by method
/// M (opennessRowIsVector says which), kWidth voxels at a time, with q = query[i] (doubles,
/// or a raw row's own 16-bit values) or isoValue where query is null; `plain(begin)` does
/// the voxels from `begin` on (the row's tail). The row loops below take q alike.
template <Method M, class Row, class Q, class Plain>
VAO_LANES_ENTRY void opennessRowLanes(
  const Row& row, const Q* query, double isoValue, float* openness, Plain&& plain)
{
  const D roundingVariance = set1(row.roundingVariance);
  const D roundingSpread = set1(flatRoundingSpread(row.roundingVariance));
  std::int64_t i = 0;
  for (; i + kWidth <= row.size; i += kWidth)
  {
    const D q = query ? loadAsDoubles(query + i) : set1(isoValue);
    const D mean = load(row.mean + i);
    D open = zero();
    if constexpr (M == Method::Chebyshev)
      open = chebyshevOpenness(q, mean, load(row.variance + i), roundingVariance, roundingSpread);
#if VAO_VECTOR_MATH
    else if constexpr (M == Method::CdfReconstruction)
      open = cdfReconstruction(q, mean, load(row.minimum + i), load(row.maximum + i));
    else
      open = gaussianCdf(q, mean, load(row.variance + i), roundingVariance, roundingSpread);
#endif
    storeFloats(openness + i, open);
  }
  plain(i);
}

#if VAO_VECTOR_MATH
/// CDF Reconstruction on a raw row (NeighbourhoodRow::raw) of voxels of type T (int16 or
/// uint16), kWidth at a time: the extrema and the means formed in the lanes as the widening
/// passes and meanVarianceRowExact form them (exact conversions, then the same division),
/// so the bits are opennessRowLanes'.
template <class T, class Row, class Q, class Plain>
VAO_LANES_ENTRY void cdfReconstructionRawLanes(
  const Row& row, const Q* query, double isoValue, float* openness, Plain&& plain)
{
  const T* minimum = static_cast<const T*>(row.raw.minimum);
  const T* maximum = static_cast<const T*>(row.raw.maximum);
  const D yz = set1(static_cast<double>(row.countYZ));
  std::int64_t i = 0;
  for (; i + kWidth <= row.size; i += kWidth)
  {
    const D q = query ? loadAsDoubles(query + i) : set1(isoValue);
    const D count = mul(smallIntegersToDouble(loadIntegers(row.countX + i)), yz);
    const D mean = div(loadAsDoubles(row.raw.sum + i), count);
    storeFloats(openness + i,
      cdfReconstruction(q, mean, loadAsDoubles(minimum + i), loadAsDoubles(maximum + i)));
  }
  plain(i);
}
#endif

/// The lanes whose integer sum lies within +-2^50, where its conversion and small multiples
/// are exact.
VAO_LANES Mask smallSums(I s)
{
  return both(
    lessThan(s, set1(std::int64_t(1) << 50)), lessThan(set1(-(std::int64_t(1) << 50)), s));
}

/// kWidth exact sums from p as doubles (total), and the lanes where that conversion and
/// small multiples are exact: sums of magnitude below 2^50, and every 32-bit sum.
VAO_LANES Mask loadSums(const std::int64_t* p, D& total)
{
  const I s = loadIntegers(p);
  total = smallIntegersToDouble(s);
  return smallSums(s);
}
VAO_LANES Mask loadSums(const std::int32_t* p, D& total)
{
  total = loadAsDoubles(p);
  return everyLane();
}

/// The kWidth boxes from box i in doubles: their counts c (countX times yz), sums S (64- or
/// 32-bit, S), S^2 and numerators c sumSquares - S^2 (exactSumsNumerator before its clamp
/// at 0), when all are exact (sums of magnitude below 2^50, both products below 2^52);
/// false otherwise.
template <class S>
VAO_LANES bool exactBoxes(const S* sum, const std::int64_t* sumSquares, const std::int64_t* countX,
  D yz, std::int64_t i, D& c, D& total, D& totalSquared, D& numerator)
{
  const D exact = set1(4503599627370496.0); // 2^52
  const Mask small = loadSums(sum + i, total);
  const I s2 = loadIntegers(sumSquares + i);
  if (!all(both(small, lessThan(s2, set1(std::int64_t(1) << 50)))))
    return false;
  c = mul(smallIntegersToDouble(loadIntegers(countX + i)), yz);
  const D a = mul(c, smallIntegersToDouble(s2));
  totalSquared = mul(total, total);
  numerator = sub(a, totalSquared);
  return none(either(greaterEqual(a, exact), greaterEqual(totalSquared, exact)));
}

/// meanVarianceRowExact (MomentRows.h), kWidth boxes at a time: count * sumSquares - sum^2
/// in doubles, exact while both products stay below 2^52; `plain(end, begin)` does the
/// boxes of [begin, end) that could leave that range, and the row's tail. Without
/// sumSquares, the counts and means alone.
template <class Plain>
VAO_LANES_ENTRY void meanVarianceRowLanes(const std::int64_t* sum, const std::int64_t* sumSquares,
  const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, double* count, double* mean,
  double* variance, Plain&& plain)
{
  const D yz = set1(static_cast<double>(countYZ));
  if (!sumSquares) // the means alone: sums below 2^50 in magnitude convert exactly
  {
    for (std::int64_t i = 0; i + kWidth <= n; i += kWidth)
    {
      const I s = loadIntegers(sum + i);
      if (!all(smallSums(s)))
      {
        plain(i + kWidth, i);
        continue;
      }
      const D c = mul(smallIntegersToDouble(loadIntegers(countX + i)), yz);
      store(count + i, c);
      store(mean + i, div(smallIntegersToDouble(s), c));
    }
    plain(n, n - n % kWidth);
    return;
  }
  for (std::int64_t i = 0; i + kWidth <= n; i += kWidth)
  {
    D c, total, totalSquared, numerator;
    if (exactBoxes(sum, sumSquares, countX, yz, i, c, total, totalSquared, numerator))
    {
      store(count + i, c);
      store(mean + i, div(total, c));
      store(variance + i, onlyWhere(greaterThan(numerator, zero()), div(numerator, mul(c, c))));
      continue;
    }
    plain(i + kWidth, i);
  }
  plain(n, n - n % kWidth);
}

/// opennessFromExactSums (Chebyshev or the Gaussian CDF, by M) of n boxes from their exact
/// sums (64- or 32-bit, S), kWidth at a time, with q_i = query[i] (isoValue where query is
/// null): c, S and N in doubles, exact while c sumSquares and S^2 stay below 2^52 (as
/// meanVarianceRowLanes); `plain(end, begin)` does the boxes of [begin, end) that could
/// leave that range, and the row's tail.
template <Method M, class S, class Q, class Plain>
VAO_LANES_ENTRY void opennessFromExactSumsLanes(const S* sum, const std::int64_t* sumSquares,
  const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, const Q* query, double isoValue,
  float* openness, Plain&& plain)
{
  const D yz = set1(static_cast<double>(countYZ));
  const D one = set1(1.0);
  for (std::int64_t i = 0; i + kWidth <= n; i += kWidth)
  {
    D c, total, totalSquared, numerator;
    if (exactBoxes(sum, sumSquares, countX, yz, i, c, total, totalSquared, numerator))
    {
      const D positive = onlyWhere(greaterThan(numerator, zero()), numerator);
      const D q = query ? loadAsDoubles(query + i) : set1(isoValue);
      const D d = sub(mul(q, c), total);
      const Mask flat = lessEqual(positive, zero());
      const D flatOpen =
        onlyWhere(greaterEqual(d, sub(zero(), mul(set1(kFlatSpread), abs(total)))), one);
      D open = zero();
      if constexpr (M == Method::Chebyshev)
      {
        const D share = div(positive, add(positive, mul(d, d)));
        open = onlyWhere(greaterThan(d, zero()), min(max(sub(one, share), zero()), one));
      }
#if VAO_VECTOR_MATH
      else
      {
        // As gaussianCdf, groups whose lanes are flat or beyond |z| = 6 (d^2 > 72 N), where
        // erf is +-1 in doubles, skip the erf, and here the division and the square root
        // too: the test waits on neither.
        if (all(either(greaterThan(mul(d, d), mul(set1(72.0), positive)), flat)))
          open = onlyWhere(greaterThan(d, zero()), one);
        else
        {
          const D z = div(d, sqrt(mul(set1(2.0), select(flat, one, positive))));
          open = min(max(mul(set1(0.5), add(one, erf(z))), zero()), one);
        }
      }
#endif
      storeFloats(openness + i, select(flat, flatOpen, open));
      continue;
    }
    plain(i + kWidth, i);
  }
  plain(n, n - n % kWidth);
}

/// This width's row loops for a dispatch written once over the widths (EstimatorRows.cxx):
/// on a row's statistics, on its exact sums, and on a raw row.
struct RowLoops
{
  template <Method M, class Row, class Q, class Plain>
  static void onStatistics(
    const Row& row, const Q* query, double isoValue, float* openness, Plain&& plain)
  {
    opennessRowLanes<M>(row, query, isoValue, openness, plain);
  }
  template <Method M, class Row, class Q, class Plain>
  static void onExactSums(
    const Row& row, const Q* query, double isoValue, float* openness, Plain&& plain)
  {
    if (row.raw.sum)
      opennessFromExactSumsLanes<M>(row.raw.sum, row.sumSquares, row.countX, row.countYZ, row.size,
        query, isoValue, openness, plain);
    else
      opennessFromExactSumsLanes<M>(row.sum, row.sumSquares, row.countX, row.countYZ, row.size,
        query, isoValue, openness, plain);
  }
#if VAO_VECTOR_MATH
  template <class T, class Row, class Q, class Plain>
  static void cdfReconstructionOnRaw(
    const Row& row, const Q* query, double isoValue, float* openness, Plain&& plain)
  {
    cdfReconstructionRawLanes<T>(row, query, isoValue, openness, plain);
  }
#endif
};
