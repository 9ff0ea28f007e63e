"""vtkVolumetricAmbientOcclusion against docs/methods.md computed exactly, on random small volumes.

Each case draws a dtype, a shape, values (small integers, a type's whole range, a CT-like
offset, flat regions with spikes, the type's two extremes, tiny or huge floats), a method,
a radius in voxels or in world units over anisotropic spacing, a query (the voxel's value
or an iso value), a bin count and an extent that does not start at 0. The reference sums
the box in Python integers or Fractions (so its statistics are exact, never the library's
helpers) and applies the definitions of docs/methods.md; the filter's float32 must agree to
a few float ulps. A second part checks that an offset or a change of unit leaves every
moment method's openness as it was (the estimators depend on (q - mu) / sigma alone).

usage: python3 test_exact_reference.py PACKAGE_DIR [SEED] [CASES]
"""
import math
import sys
from fractions import Fraction

sys.path.insert(0, sys.argv[1])
import numpy as np  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from volumetricao import VolumetricAOFilters  # noqa: E402
from vao_test_utils import check, finish, summary  # noqa: E402

F = VolumetricAOFilters.vtkVolumetricAmbientOcclusion
seed = int(sys.argv[2]) if len(sys.argv) > 2 else 20261205
cases = int(sys.argv[3]) if len(sys.argv) > 3 else 120
rng = np.random.default_rng(seed)

TYPES = [np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.int64, np.uint64, np.float32, np.float64]
METHODS = ["GAUSSIAN_CDF", "CHEBYSHEV", "CDF_RECONSTRUCTION", "EXACT_BOX", "EXACT_SPHERE", "HISTOGRAM_CDF"]


def draw_values(dt, n):
    integral = np.issubdtype(dt, np.integer)
    lo, hi = (float(np.iinfo(dt).min), float(np.iinfo(dt).max)) if integral else (-1e30, 1e30)
    if integral and np.dtype(dt).itemsize == 8:
        lo, hi = max(lo, -2.0 ** 50), min(hi, 2.0 ** 50)  # doubles hold them: exact statistics
    kind = rng.integers(0, 6)
    if kind == 0:
        a = rng.integers(0, 5, n).astype(np.float64)
    elif kind == 1:
        a = np.floor(rng.uniform(lo, hi, n)) if integral else rng.uniform(-1.0, 1.0, n) * 1e30
    elif kind == 2:
        a = 1000.0 + rng.integers(-3, 4, n)
    elif kind == 3:
        a = np.where(rng.random(n) < 0.05, 90.0, 7.0)
    elif kind == 4:
        a = np.where(rng.random(n) < 0.5, lo, hi)
    else:
        a = rng.standard_normal(n) * (1e-30 if rng.random() < 0.5 else 1e20) if not integral else rng.integers(0, 200, n) * 1.0
    a = np.clip(np.abs(a) if np.issubdtype(dt, np.unsignedinteger) else a, lo, hi)
    return a.astype(dt)


def exact(x):
    return int(x) if isinstance(x, (int, np.integer)) else Fraction(float(x))


def reference(v, radii, method, iso, bins):
    """docs/methods.md section 1-5 and section 8 with exact statistics; NaN where a case is not decided here."""
    nz, ny, nx = v.shape
    flat_values = v.reshape(-1)
    values = [exact(x) for x in flat_values]
    # 64-bit integers compare as doubles (docs/methods.md counts double(v) <= q, as VTK does).
    compared = [float(x) for x in flat_values] if v.dtype.itemsize == 8 and v.dtype.kind in "iu" else values
    distinct = sorted(set(values))
    rx, ry, rz = radii
    out = np.full(v.size, np.nan)
    variance = np.zeros(v.size)
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                i = (z * ny + y) * nx + x
                box, counted, sphere = [], [], []
                for zz in range(max(0, z - rz), min(nz, z + rz + 1)):
                    for yy in range(max(0, y - ry), min(ny, y + ry + 1)):
                        for xx in range(max(0, x - rx), min(nx, x + rx + 1)):
                            j = (zz * ny + yy) * nx + xx
                            box.append(values[j])
                            counted.append(compared[j])
                            inside = all((d == 0) if r == 0 else True for d, r in ((xx - x, rx), (yy - y, ry), (zz - z, rz)))
                            s = sum(Fraction(d * d, r * r) for d, r in ((xx - x, rx), (yy - y, ry), (zz - z, rz)) if r)
                            if inside and s <= 1:
                                sphere.append(compared[j])
                c = len(box)
                mu = Fraction(sum(box), c)
                s2 = Fraction(sum(b * b for b in box), c) - mu * mu
                try:
                    variance[i] = float(s2)
                except OverflowError:
                    variance[i] = math.inf
                q = values[i] if iso is None else Fraction(iso)
                qc = compared[i] if iso is None else iso
                if method == "EXACT_BOX":
                    out[i] = sum(1 for b in counted if b <= qc) / c
                elif method == "EXACT_SPHERE":
                    out[i] = sum(1 for b in sphere if b <= qc) / len(sphere)
                elif method == "HISTOGRAM_CDF":
                    # With at most `bins` distinct values the thresholds are the values (8.).
                    if len(distinct) <= bins and (iso is None or q in distinct):
                        out[i] = sum(1 for b in counted if b <= qc) / c
                elif s2 == 0:
                    out[i] = 1.0 if q >= mu else 0.0
                elif method == "GAUSSIAN_CDF":
                    z2 = (q - mu) ** 2 / (2 * s2)
                    out[i] = 0.5 * (1.0 + math.erf(math.copysign(math.sqrt(float(z2)), float(q - mu))))
                elif method == "CHEBYSHEV":
                    d = q - mu
                    out[i] = 0.0 if d <= 0 else float(1 - s2 / (s2 + d * d))
                else:
                    lo, hi = min(box), max(box)
                    t = (q - lo) / (hi - lo)
                    beta = (mu - lo) / (hi - mu)
                    out[i] = 1.0 if t >= 1 else (0.0 if t <= 0 else float(t) ** float(beta))
    return out.reshape(v.shape), variance.reshape(v.shape)


def run(v, method, radius, world, spacing, extent0, iso, bins, smoothing=None):
    image = vtkImageData()
    nz, ny, nx = v.shape
    image.SetExtent(extent0[0], extent0[0] + nx - 1, extent0[1], extent0[1] + ny - 1, extent0[2], extent0[2] + nz - 1)
    image.SetSpacing(*spacing)
    scalars = numpy_to_vtk(np.ascontiguousarray(v).reshape(-1), deep=1)
    scalars.SetName("values")
    image.GetPointData().SetScalars(scalars)
    f = F()
    f.SetInputData(image)
    f.SetMethod(getattr(F, method))
    f.SetRadius(radius)
    f.SetRadiusUnits(F.WORLD if world else F.VOXELS)
    f.SetNumberOfBins(bins)
    f.SetComputeVariance(True)
    f.SetBackend(F.BACKEND_CPU)
    if iso is not None:
        f.SetQueryMode(F.ISO_VALUE)
        f.SetIsoValue(iso)
    elif smoothing is not None:
        f.SetQueryMode(F.SMOOTHED_VALUE)
        f.SetQuerySmoothing(smoothing)
    f.Update()
    data = f.GetOutput().GetPointData()
    arrays = [data.GetArray(name) for name in ("AmbientOcclusion", "Variance")]
    if any(a is None for a in arrays):
        return None, None
    return [vtk_to_numpy(a).reshape(v.shape).astype(np.float64) for a in arrays]


compared_cases = 0
for k in range(cases):
    dt = TYPES[rng.integers(len(TYPES))]
    shape = tuple(int(s) for s in rng.integers(2, 8, 3))
    v = draw_values(dt, int(np.prod(shape))).reshape(shape)
    method = METHODS[rng.integers(len(METHODS))]
    world = bool(rng.random() < 0.4)
    if world:
        spacing = tuple(float(s) for s in rng.choice([0.5, 0.7, 1.0, 1.3, 2.1], 3))
        radius = float(rng.choice([1.0, 1.6, 2.2, 3.1]))
        radii = tuple(int(math.floor(radius / h + 0.5)) for h in spacing)
    else:
        spacing, radius = (1.0, 1.0, 1.0), float(rng.integers(1, 3))
        radii = (int(radius),) * 3
    if max(radii) == 0 or all(r >= n - 1 for r, n in zip(radii, shape[::-1])):
        continue  # refused by the filter (a box of one voxel, or of the whole volume everywhere)
    iso = None
    if rng.random() < 0.3:
        base = float(v.reshape(-1)[rng.integers(v.size)])
        iso = base + float(rng.choice([0.0, 1.0, -1.0])) * max(0.5, 1e-3 * abs(base))
    bins = int(rng.choice([2, 8, 64]))
    extent0 = tuple(int(e) for e in rng.integers(-5, 6, 3))
    got, got_variance = run(v, method, radius, world, spacing, extent0, iso, bins)
    want, want_variance = reference(v, radii, method, iso, bins)
    label = "case %d: %s %s radii %s %s iso %s extent from %s bins %d" % (
        k, np.dtype(dt).name, shape, radii, method, iso, extent0, bins)
    if not check(got is not None, "an output, " + label):
        continue
    compared_cases += 1
    decided = ~np.isnan(want)
    error = np.abs(got - want)[decided].max() if decided.any() else 0.0
    check(error <= 5e-6, "openness off by %.3g (at most 5e-6), %s" % (error, label))
    # The variance to float32 precision (infinite where it overflows float32).
    big = want_variance > float(np.finfo(np.float32).max)
    relative = np.abs(got_variance - want_variance) / np.maximum(want_variance, float(np.finfo(np.float32).tiny))
    check(not ((big & ~np.isinf(got_variance)).any() or (relative[~big] > 1e-5).any()),
          "variance off by %.3g (relative, at most 1e-5; infinite beyond float32), %s"
          % (relative[~big].max() if (~big).any() else 0.0, label))

# Invariance: a soft-tissue-like field at offsets and in units far from 1.
base = np.asarray(1000 + rng.integers(-20, 21, (9, 10, 11)), dtype=np.int16)
for method, smoothing in (("GAUSSIAN_CDF", None), ("CHEBYSHEV", None), ("CDF_RECONSTRUCTION", None),
                          ("EXACT_BOX", 1.0), ("GAUSSIAN_CDF", 1.0)):
    expected, _ = run(base, method, 2.0, False, (1.0, 1.0, 1.0), (0, 0, 0), None, 64, smoothing)
    for name, values in (("int32 + 1e9", base.astype(np.int32) + 1000000000),
                         ("int64 - 1e12", base.astype(np.int64) - 10 ** 12),
                         ("float64 * 1e-10", base * 1e-10),
                         ("float64 * 1e-25 + 1e-21", base * 1e-25 + 1e-21),
                         ("float32 * 2^-60", np.ldexp(base.astype(np.float32), -60))):
        if smoothing is not None and name == "int64 - 1e12":
            continue  # a double query there resolves 1e-4: one near an integer may round to it
        got, _ = run(values, method, 2.0, False, (1.0, 1.0, 1.0), (0, 0, 0), None, 64, smoothing)
        check(got is not None and not np.abs(got - expected).max() > 1e-5,
              "%s (smoothed query %s) of %s differs from the int16 field's by %s (at most 1e-5)" % (
                  method, smoothing, name, "no output" if got is None else "%.3g" % np.abs(got - expected).max()))

check(compared_cases >= cases // 2, "%d of %d cases compared with the reference (at least half)" % (compared_cases, cases))
print("%d cases against the exact reference (seed %d): %s" % (compared_cases, seed, summary()))
finish("every case agreed with the exact reference")
