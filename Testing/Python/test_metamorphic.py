"""Every filter against itself: what must not change the answer does not change it.

On random small volumes (8- to 64-bit integers and floats, shapes of 3 to 17 voxels,
radii of 1 to 4, iso values through the data), each filter's output is compared with its
output after
- another number of threads (1 against 2, 3 and 7): the same floats, up to the rounding
  of double sums for 32- and 64-bit data, whose order follows the chunks;
- an extent that does not start at 0 (the same voxels at other indices): the same floats;
- a flip of the volume along each axis: the flipped output. The box windows are symmetric,
  so Volumetric AO of 8- and 16-bit data (exact integer sums) is the same bit for bit and
  of other data within float rounding; Occlusion Sweeping iterated to convergence within
  2e-5 (one pass of the paper's eight ordered sweeps is not symmetric, by design).
Isosurface AO (the contour's points, their AO and Shadow) is checked against threads and
extents (to 1e-5 there: the points' float coordinates round differently at other
indices), against the spacing and origin in other units (x 3.7 and x 1e-3; and on 40
smooth random fields at spacings and origins that binary fractions do not hold, x 1e-3,
3.7 or 1e4), and with one pyramid level against flips of the volume and the light (points
matched to the nearest, 1e-5). Volumetric AO with a world radius whose ratio to the
spacing is a half-integer gives the same voxels, and floats, in other units. Coarser levels sit on every 2^l-th voxel from the first,
so with more levels a flip moves their grids and the answer (docs/methods.md, Penner and
Mitchell).

usage: python3 test_metamorphic.py PACKAGE_DIR [SEED] [CASES]
"""
import sys

sys.path.insert(0, sys.argv[1])
import numpy as np  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D  # noqa: E402
from volumetricao import VolumetricAOFilters as V  # noqa: E402
from vao_test_utils import check, finish, summary  # noqa: E402

seed = int(sys.argv[2]) if len(sys.argv) > 2 else 20261205
cases = int(sys.argv[3]) if len(sys.argv) > 3 else 30
rng = np.random.default_rng(seed)


SPACING = np.array([0.5, 1.0, 1.5])
ORIGIN = np.array([-2.0, 1.0, 3.0])


def image(values, first=(0, 0, 0), unit=1.0, spacing=SPACING, origin=ORIGIN):
    result = vtkImageData()
    nz, ny, nx = values.shape
    result.SetExtent(first[0], first[0] + nx - 1, first[1], first[1] + ny - 1, first[2], first[2] + nz - 1)
    result.SetSpacing(*(np.asarray(spacing) * unit))
    result.SetOrigin(*(np.asarray(origin) * unit))
    scalars = numpy_to_vtk(np.ascontiguousarray(values).reshape(-1), deep=1)
    scalars.SetName("v")
    result.GetPointData().SetScalars(scalars)
    return result


def arrays(data, shape):
    out = {}
    point_data = data.GetPointData()
    for i in range(point_data.GetNumberOfArrays()):
        name = point_data.GetArrayName(i)
        if name != "v":
            a = vtk_to_numpy(point_data.GetArray(i))
            out[name] = a.reshape(shape + a.shape[1:]) if shape else a
    return out


def volume_run(make, values, threads=1, first=(0, 0, 0)):
    f = make()
    f.SetNumberOfThreads(threads)
    f.SetInputData(image(values, first))
    f.Update()
    o = f.GetOutput()
    if o.IsA("vtkImageData"):
        return arrays(o, values.shape)
    out = {}  # the Variance Occlusion Map's levels
    for b in range(o.GetNumberOfBlocks()):
        level = o.GetBlock(b)
        dims = level.GetDimensions()
        out.update({"%d:%s" % (b, k): a for k, a in arrays(level, (dims[2], dims[1], dims[0])).items()})
    return out


LIGHT = (0.3, -0.5, 0.8)


def isosurface(volume, iso, shadows, threads=1, levels=4, light=None):
    """Isosurface AO of the volume's own contour at iso (the filter's light unless given)."""
    contour = vtkFlyingEdges3D()
    contour.SetInputData(volume)
    contour.SetValue(0, iso)
    contour.Update()
    f = V.vtkIsosurfaceAmbientOcclusion()
    f.SetNumberOfThreads(threads)
    f.SetInputData(contour.GetOutput())
    f.SetVolumeData(volume)
    f.SetIsoValue(iso)
    f.SetComputeShadows(shadows)
    if light is not None:
        f.SetLightDirection(*light)
    f.SetNumberOfLevels(levels)
    f.Update()
    return f.GetOutput()


def surface_run(values, iso, shadows, threads=1, first=(0, 0, 0), levels=4, light=LIGHT, unit=1.0):
    """isosurface() on the values, its arrays and points (at unit 1, extent from 0) in the
    points' order."""
    o = isosurface(image(values, first, unit), iso, shadows, threads, levels, light)
    if o.GetNumberOfPoints() == 0:
        return {}
    shift = (np.array(first) * SPACING + ORIGIN) * unit
    points = (vtk_to_numpy(o.GetPoints().GetData()) - shift) / unit
    order = np.lexsort(np.round(points, 5).T[::-1])
    out = {k: a[order] for k, a in arrays(o, None).items()}
    out["points"] = points[order]
    return out


def differs(a, b, tolerance):
    if a.keys() != b.keys():
        return "arrays %s against %s" % (sorted(a), sorted(b))
    for k in a:
        x, y = a[k].astype(np.float64), b[k].astype(np.float64)
        if x.shape != y.shape:
            return "%s: shape %s against %s" % (k, x.shape, y.shape)
        if not np.array_equal(np.isnan(x), np.isnan(y)):
            return "%s: NaN in one only" % k
        gap = np.nanmax(np.abs(x - y) / (1.0 + np.abs(x) * (tolerance > 0))) if x.size else 0.0
        if gap > tolerance:
            return "%s: differs by %g (allowed %g)" % (k, gap, tolerance)
    return None


def agree(what, difference):
    """Checks that two outputs agree: `difference` is differs()'s answer for them."""
    check(difference is None, "%s: %s" % (what, difference or "the same"))


def draw():
    shape = tuple(int(n) for n in rng.integers(3, 18, 3))
    dtype = rng.choice([np.uint8, np.int8, np.int16, np.uint16, np.int32, np.int64, np.float32, np.float64])
    kind = rng.integers(0, 3)
    if kind == 0:
        a = rng.integers(0, 6, shape) * 20.0
    elif kind == 1:
        a = rng.normal(60, 30, shape)
    else:  # a block in an empty volume: flat regions and sharp edges
        a = np.zeros(shape)
        centre = rng.integers(0, shape)
        a[tuple(slice(max(0, c - 3), c + 3) for c in centre)] = 100
    if np.issubdtype(dtype, np.integer):
        a = np.clip(np.round(a), np.iinfo(dtype).min, np.iinfo(dtype).max)
    return a.astype(dtype)


def volumetric(method, radius, query, iso):
    def make():
        f = V.vtkVolumetricAmbientOcclusion()
        f.SetMethod(method)
        f.SetRadius(radius)
        f.SetComputeVariance(True)
        f.SetQueryMode(query)
        f.SetIsoValue(iso)
        f.SetQuerySmoothing(1.0)
        return f
    return make


def sweeping(iso, converged):
    def make():
        f = V.vtkOcclusionSweeping()
        f.SetIsoValue(iso)
        f.SetOutputOctantVisibility(not converged)
        if converged:
            f.SetNumberOfIterations(100)
            f.SetConvergenceTolerance(1e-7)
        return f
    return make


def pyramid(levels):
    def make():
        f = V.vtkVarianceOcclusionMap()
        f.SetNumberOfLevels(levels)
        return f
    return make


F = V.vtkVolumetricAmbientOcclusion
for case in range(cases):
    values = draw()
    exact = values.dtype.itemsize <= 2 and np.issubdtype(values.dtype, np.integer)
    radius = int(rng.integers(1, 5))
    iso = float(np.median(values)) + 0.5
    label = "case %d (%s %s, R = %d)" % (case, values.dtype, values.shape, radius)
    makers = [("%s" % m, volumetric(getattr(F, m), radius, F.VOXEL_VALUE, iso), exact)
              for m in ["GAUSSIAN_CDF", "CHEBYSHEV", "CDF_RECONSTRUCTION", "HISTOGRAM_CDF"]]
    makers += [("GAUSSIAN_CDF iso", volumetric(F.GAUSSIAN_CDF, radius, F.ISO_VALUE, iso), exact),
               ("EXACT_BOX smoothed", volumetric(F.EXACT_BOX, radius, F.SMOOTHED_VALUE, iso), False),
               ("sweeping, one pass", sweeping(iso, False), None),
               ("sweeping, converged", sweeping(iso, True), False),
               ("variance occlusion map", pyramid(int(rng.integers(1, 4))), None)]
    with_threads = 0.0 if exact else 5e-7
    for name, make, symmetric in makers:
        what = "%s, %s" % (label, name)
        base = volume_run(make, values)
        if not base:
            continue
        for threads in (2, 3, 7):
            agree("%s, %d threads" % (what, threads), differs(base, volume_run(make, values, threads), with_threads))
        agree("%s, extent from (5, -3, 7)" % what, differs(base, volume_run(make, values, first=(5, -3, 7)), 0.0))
        if symmetric is None:
            continue
        for axis in range(3):
            flipped = volume_run(make, np.flip(values, 2 - axis).copy())
            flipped = {k: np.flip(a, 2 - axis) for k, a in flipped.items()}
            agree("%s, flipped along axis %d" % (what, axis), differs(base, flipped, 0.0 if symmetric else 2e-5))
    if values.dtype in (np.int16, np.float32) and values.min() < iso < values.max():
        shadows = bool(case % 2)
        base = surface_run(values, iso, shadows)
        what = "%s, isosurface AO%s" % (label, " + shadows" if shadows else "")
        for threads in (2, 7):
            agree("%s, %d threads" % (what, threads), differs(base, surface_run(values, iso, shadows, threads), 0.0))
        agree("%s, extent from (5, -3, 7)" % what,
              differs(base, surface_run(values, iso, shadows, first=(5, -3, 7)), 1e-5))
        for unit in (3.7, 1e-3):  # spacing and origin in other units: the same scene
            agree("%s, spacing and origin x %g" % (what, unit),
                  differs(base, surface_run(values, iso, shadows, unit=unit), 1e-5))
        one = surface_run(values, iso, True, levels=1)
        extent = (np.array(values.shape[::-1]) - 1) * SPACING
        for axis in range(3):
            light = list(LIGHT)
            light[axis] = -light[axis]
            flipped = surface_run(np.flip(values, 2 - axis).copy(), iso, True, levels=1, light=light)
            points = flipped.pop("points")
            points[:, axis] = extent[axis] - points[:, axis]
            distance, nearest = cKDTree(points).query(one["points"])
            flipped = {k: a[nearest] for k, a in flipped.items()}
            if "Normals" in flipped:
                flipped["Normals"] = flipped["Normals"] * np.where(np.arange(3) == axis, -1.0, 1.0)
            flipped["points"] = one["points"] if distance.max() < 1e-5 else points[nearest]
            agree("%s, one level, flipped along axis %d" % (what, axis), differs(one, flipped, 1e-5))
# Isosurface AO and shadows of smooth random fields (whose surfaces the coarse levels and
# the long marches see) at a spacing and origin that binary fractions do not hold, then
# the same scene in other units: the march's levels change at t / r0 + 1 = 2^l whatever
# the unit's rounding.
for case in range(40):
    shape = tuple(int(n) for n in rng.integers(10, 21, 3))
    field = rng.normal(0.0, 1.0, shape)
    for _ in range(2):
        field = (field + np.roll(field, 1, 0) + np.roll(field, 1, 1) + np.roll(field, 1, 2)) / 2
    spacing, origin = rng.uniform(0.3, 2.0, 3), rng.uniform(-5.0, 5.0, 3)
    unit = float(rng.choice([1e-3, 3.7, 1e4]))
    one, other = (arrays(isosurface(image(field.astype(np.float32), unit=u, spacing=spacing, origin=origin), 0.2, True),
                         None) for u in (1.0, unit))
    agree("smooth field %d %s, isosurface AO + shadows, spacing and origin x %g" % (case, shape, unit),
          differs({k: one[k] for k in ("AmbientOcclusion", "Shadow")},
                  {k: other[k] for k in ("AmbientOcclusion", "Shadow")}, 1e-5))
# A radius in world units over a spacing whose ratio is a half-integer (5.5 x 1.3 over 1.3)
# rounds to the same voxels in any unit, though in some the ratio comes out an ulp below.
values = (rng.integers(0, 5, (14, 15, 16)) * 10).astype(np.int16)
for h, ratio, unit in [(1.3, 5.5, 1e-3), (0.15, 1.5, 25.4), (0.15, 4.5, 10.0), (0.8, 3.5, 1e-3)]:
    outputs = []
    for u in (1.0, unit):
        volume = image(values, unit=u, spacing=(h, h, h))
        f = V.vtkVolumetricAmbientOcclusion()
        f.SetRadiusUnits(F.WORLD)
        f.SetRadius(ratio * h * u)
        f.SetInputData(volume)
        f.Update()
        outputs.append(arrays(f.GetOutput(), values.shape))
    agree("world radius %g x %g in units x %g" % (ratio, h, unit), differs(outputs[0], outputs[1], 0.0))
print("%d cases: %s" % (cases, summary()))
finish("every filter gave the same answer where it must")
