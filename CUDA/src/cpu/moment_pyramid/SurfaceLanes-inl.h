// The surface queries' Chebyshev lanes (LevelGrid.h's definition) on a width of doubles,
// written once over DoubleLanes.h and GatherLanes.h and included by SurfaceLanes.h into
// the avx2 and the avx512 namespace: a cell's corners gathered through 32-bit indices,
// the trilinear blend and the estimator in vector arithmetic, and the whole shadow march
// of a batch in registers, so one step is few enough instructions for the processor to
// overlap the loads' latency of several. Equal to the plain loops but for the rounding of
// the blends' fused multiply-adds; the march passes over the samples that their cell's
// bound (CellBounds) shows cannot raise a lane's occlusion, which changes no maximum.
// No include guard: included once per namespace, with VAO_LANES its inline target.

/// The vectors of a batch.
constexpr int kVectors = kLanes / kWidth;

VAO_LANES D lerp(D a, D b, D t)
{
  return fusedMultiplyAdd(t, sub(b, a), a);
}

/// The cells of one level under kWidth positions: the lower corners as flat 32-bit
/// indices (LevelGrid's layout, tiled or not), the steps to the upper corners per axis
/// (0 where clamped) and the fractions towards them.
struct Cells
{
  Idx base;
  Idx step[3];
  D f[3];
};

VAO_LANES Cells cellsOf(const LevelGrid& g, const D* position)
{
  Cells c;
  c.base = indices(0);
  Idx tile = indices(0);
  for (int a = 0; a < 3; ++a)
  {
    const D maxIndex = set1(g.maxIndex[a]);
    const D u = min(
      max(mul(sub(position[a], set1(g.origin[a])), set1(g.inverseSpacing[a])), zero()), maxIndex);
    Idx lower = truncate(u);
    if (a == 0 && g.pairedRows) // the last voxel as the upper corner of the cell below it
      lower = min(lower, indices(static_cast<std::int64_t>(g.maxIndex[0]) - 1));
    c.f[a] = sub(u, toDouble(lower));
    const Idx stride = indices(g.stride[a]);
    if (g.tiled) // trilinearSample's tiled index: the tile, and the corner within it
    {
      tile = add(tile, mul(eighth(lower), indices(g.tileStride[a])));
      c.base = add(c.base, mul(remainderOfEight(lower), stride));
    }
    else
      c.base = add(c.base, mul(lower, stride));
    c.step[a] = onlyWhere(lessThan(u, maxIndex), stride);
  }
  if (g.tiled)
    c.base = add(c.base, gather(g.tileOffsets, tile));
  return c;
}

/// The lower x corners of the cells' four x rows: (y, z), (y + 1, z), (y, z + 1),
/// (y + 1, z + 1).
VAO_LANES void rowsOf(const Cells& c, Idx* row)
{
  row[0] = c.base;
  row[1] = add(c.base, c.step[1]);
  row[2] = add(c.base, c.step[2]);
  row[3] = add(row[2], c.step[1]);
}

/// The trilinear mean and variance (not yet clamped) of the cells: the four x rows of
/// each cell, lerped along x, then y, then z (trilinearSample's order).
VAO_LANES void blend(const LevelGrid& g, const Cells& c, D& mean, D& variance)
{
  Idx row[4];
  rowsOf(c, row);
  D means[4], variances[4];
  for (int r = 0; r < 4; ++r)
  {
    const Idx upper = add(row[r], c.step[0]);
    if (g.tiled) // (mean, variance) pairs: one 64-bit gather per corner
    {
      D m[2], v[2];
      gatherPairs<4>(g.mean, row[r], m[0], v[0]);
      gatherPairs<4>(g.mean, upper, m[1], v[1]);
      means[r] = lerp(m[0], m[1], c.f[0]);
      variances[r] = lerp(v[0], v[1], c.f[0]);
    }
    else if (g.pairedRows) // a row's two x corners: one 64-bit gather
    {
      D lo, hi;
      gatherPairs<4>(g.mean, row[r], lo, hi);
      means[r] = lerp(lo, hi, c.f[0]);
      gatherPairs<4>(g.variance, row[r], lo, hi);
      variances[r] = lerp(lo, hi, c.f[0]);
    }
    else
    {
      means[r] = lerp(gatherFloats(g.mean, row[r]), gatherFloats(g.mean, upper), c.f[0]);
      variances[r] =
        lerp(gatherFloats(g.variance, row[r]), gatherFloats(g.variance, upper), c.f[0]);
    }
  }
  mean = lerp(lerp(means[0], means[1], c.f[1]), lerp(means[2], means[3], c.f[1]), c.f[2]);
  variance = lerp(
    lerp(variances[0], variances[1], c.f[1]), lerp(variances[2], variances[3], c.f[1]), c.f[2]);
}

/// The Chebyshev occlusion of q in the cells (occlusionLanesPlain's formula).
VAO_LANES D chebyshevOcclusion(const LevelGrid& g, const Cells& c, D q)
{
  D mean, variance;
  blend(g, c, mean, variance);
  return sub(set1(1.0),
    chebyshevOpenness(
      q, mean, max(variance, zero()), set1(g.roundingVariance), set1(g.roundingSpread)));
}

/// Upper bounds of the Chebyshev occlusion of q from (largest mean, largest variance)
/// pairs indexed like the cells (CellBounds, RayBounds): 1 where q is not above the mean
/// or the bound is NaN.
VAO_LANES D chebyshevBound(const float* pairs, const Cells& c, D q)
{
  D mean, variance;
  gatherPairs<8>(pairs, c.base, mean, variance);
  const D d = sub(q, mean);
  const D share = div(variance, add(variance, mul(d, d)));
  return select(both(greaterThan(d, zero()), ordered(share)), share, set1(1.0));
}

/// Asks for the cache lines of the cells' rows (x pairs) at the lanes' positions, so that
/// a batch's samples of a level far larger than the caches wait on their misses together.
VAO_LANES_ENTRY void prefetchLanes(
  const LevelGrid& g, const double* x, const double* y, const double* z)
{
  for (int h = 0; h < kLanes; h += kWidth)
  {
    const D position[3] = { load(x + h), load(y + h), load(z + h) };
    Idx rows[4];
    rowsOf(cellsOf(g, position), rows);
    alignas(64) std::int32_t at[4][kWidth];
    for (int r = 0; r < 4; ++r)
      storeIndices(at[r], rows[r]);
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < kWidth; ++k)
      {
        _mm_prefetch(reinterpret_cast<const char*>(g.mean + at[r][k]), _MM_HINT_T0);
        if (!g.tiled)
          _mm_prefetch(reinterpret_cast<const char*>(g.variance + at[r][k]), _MM_HINT_T0);
      }
  }
}

/// The raw values base[at[k]] as doubles, whatever the volume's type: one load a lane.
/// Floats gather as the levels' do; types of up to 16 bits go through one vector of 32-bit
/// integers and one conversion (rather than a conversion a lane).
template <class T>
VAO_LANES D gatherAsDoubles(const T* base, Idx at)
{
  if constexpr (std::is_same<T, float>::value)
    return gatherFloats(base, at);
  else
  {
    alignas(32) std::int32_t i[kWidth];
    storeIndices(i, at);
    if constexpr (std::is_integral<T>::value && sizeof(T) <= 2)
    {
      alignas(32) std::int32_t v[kWidth];
      for (int k = 0; k < kWidth; ++k)
        v[k] = base[i[k]];
      return toDouble(loadIndices(v));
    }
    else
    {
      alignas(64) double v[kWidth];
      for (int k = 0; k < kWidth; ++k)
        v[k] = static_cast<double>(base[i[k]]);
      return load(v);
    }
  }
}

/// A row's blend along x: v0 (1 - f) + v1 f, with g = 1 - f.
template <class T>
VAO_LANES D rawRow(const T* data, Idx at, Idx step, D g, D f)
{
  return add(mul(gatherAsDoubles(data, at), g), mul(gatherAsDoubles(data, add(at, step)), f));
}

/// RawSampler's values at kLanes positions: its clamps, cells and blends, operation for
/// operation (no fused multiply-add), so the same bits.
template <class T>
VAO_LANES_ENTRY void rawLanes(
  const RawSampler<T>& s, const double* x, const double* y, const double* z, double* out)
{
  const D one = set1(1.0);
  for (int h = 0; h < kLanes; h += kWidth)
  {
    const D position[3] = { load(x + h), load(y + h), load(z + h) };
    Idx base = indices(0), step[3];
    D f[3], g[3]; // the fractions towards the upper corners, and 1 - them
    for (int a = 0; a < 3; ++a)
    {
      const D maxIndex = set1(s.maxIndex[a]);
      // max(x, 0) gives 0 for NaN, as RawSampler's std::max(0.0, x) does.
      const D u = min(
        max(mul(sub(position[a], set1(s.origin[a])), set1(s.inverseSpacing[a])), zero()), maxIndex);
      const Idx lower = truncate(u);
      f[a] = sub(u, toDouble(lower));
      g[a] = sub(one, f[a]);
      const Idx stride = indices(s.stride[a]);
      base = add(base, mul(lower, stride));
      step[a] = onlyWhere(lessThan(u, maxIndex), stride);
    }
    const Idx upper = add(base, step[2]);
    const D lowerPlane = add(mul(rawRow(s.data, base, step[0], g[0], f[0]), g[1]),
      mul(rawRow(s.data, add(base, step[1]), step[0], g[0], f[0]), f[1]));
    const D upperPlane = add(mul(rawRow(s.data, upper, step[0], g[0], f[0]), g[1]),
      mul(rawRow(s.data, add(upper, step[1]), step[0], g[0], f[0]), f[1]));
    store(out + h, add(mul(lowerPlane, g[2]), mul(upperPlane, f[2])));
  }
}

/// trilinearSample's means at kLanes positions, but for the rounding of the blends' fused
/// multiply-adds.
VAO_LANES_ENTRY void meanLanes(
  const LevelGrid& g, const double* x, const double* y, const double* z, double* mean)
{
  for (int h = 0; h < kLanes; h += kWidth)
  {
    const D position[3] = { load(x + h), load(y + h), load(z + h) };
    D m, variance;
    blend(g, cellsOf(g, position), m, variance);
    store(mean + h, m);
  }
}

/// occlusionLanesPlain for Chebyshev.
VAO_LANES_ENTRY void chebyshevLanes(const LevelGrid& g, const double* x, const double* y,
  const double* z, const double* query, double* occlusion)
{
  for (int h = 0; h < kLanes; h += kWidth)
  {
    const D position[3] = { load(x + h), load(y + h), load(z + h) };
    store(occlusion + h, chebyshevOcclusion(g, cellsOf(g, position), load(query + h)));
  }
}

/// The Chebyshev shadow march of a batch (batchMarch in SurfaceSampling.cxx, whose rules
/// it follows lane by lane) with the positions, bounds, occlusions and the lanes still
/// marching in registers: from start (x, y, z per lane) along the unit light, inside
/// [lo, hi], the steps of `schedule` (marchSchedule), on levels whose indices fit in 32
/// bits. `rays`: null, or the RayBounds of level `rayLevel`, the schedule's last.
VAO_LANES_ENTRY void chebyshevMarch(const LevelGrid* grids, const MarchStep* schedule,
  std::size_t steps, const double* lo, const double* hi, const double* const* start,
  const double* light, const double* query, double* occlusion, const float* rays, int rayLevel)
{
  const D full = set1(kMarchFullOcclusion);
  D occ[kVectors], q[kVectors], from[kVectors][3];
  Mask alive[kVectors];
  for (int h = 0; h < kVectors; ++h)
  {
    occ[h] = zero();
    alive[h] = everyLane();
    q[h] = load(query + kWidth * h);
    for (int a = 0; a < 3; ++a)
      from[h][a] = load(start[a] + kWidth * h);
  }
  for (std::size_t s = 0; s < steps; ++s)
  {
    const double t = schedule[s].t;
    D at[kVectors][3];
    bool any = false;
    for (int h = 0; h < kVectors; ++h)
    {
      for (int a = 0; a < 3; ++a)
      {
        // start + t * light rounded as the plain loop does (no fused multiply-add): both
        // forms stop at the same step on a bound.
        at[h][a] = add(from[h][a], mul(set1(t), set1(light[a])));
        alive[h] = both(
          alive[h], both(greaterEqual(at[h][a], set1(lo[a])), lessEqual(at[h][a], set1(hi[a]))));
      }
      any = any || !none(alive[h]);
    }
    if (!any)
      break;
    const LevelGrid& grid = grids[schedule[s].level];
    for (int h = 0; h < kVectors; ++h)
    {
      if (none(alive[h]))
        continue;
      const Cells cells = cellsOf(grid, at[h]);
      // No lane still marching can rise above its occlusion here: the sample is passed
      // over, as the maximum it would enter is already held. Lanes that nothing on the
      // rest of their ray can raise stop.
      if (grid.cellBounds &&
        none(butNot(alive[h], lessEqual(chebyshevBound(grid.cellBounds, cells, q[h]), occ[h]))))
      {
        if (rays && schedule[s].level == rayLevel)
          alive[h] = butNot(alive[h], lessEqual(chebyshevBound(rays, cells, q[h]), occ[h]));
        continue;
      }
      const D sample = chebyshevOcclusion(grid, cells, q[h]);
      occ[h] = select(alive[h], max(sample, occ[h]), occ[h]);
      alive[h] = both(alive[h], lessThan(occ[h], full));
    }
  }
  for (int h = 0; h < kVectors; ++h)
    store(occlusion + kWidth * h, occ[h]);
}
