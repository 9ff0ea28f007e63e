"""The numpy functions of volumetricao speak numpy (python3 or pvpython): their messages
name voxels, shapes and axes in array order [z, y, x] and numpy's remedies, not VTK's
(x, y, z) and ParaView's filters, and they refuse what the filters refuse, no more; every
numeric argument refuses strings, bytes and bools with a TypeError naming it, and every
integer argument refuses floats.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_numpy_terms.py SITE_PACKAGES_DIR"""
import re
import sys
import warnings

site = sys.argv[1]
sys.path.insert(0, site)
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from volumetricao import _common  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
from vtkmodules.vtkCommonCore import vtkCommand, vtkPoints  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData  # noqa: E402

from vao_test_utils import check, finish, same  # noqa: E402

# VTK's order of a numpy index or shape, and ParaView's remedies: none may be left.
VTK_WORDS = re.compile(r"Calculator|Threshold filters|Change Spacing|Contour|Clean\)|set Component|LightDirection")


def error_of(call, kind=ValueError):
    """The message of the `kind` that call() raises ("" if it raises nothing, the other
    exception's type and text if it raises another)."""
    try:
        call()
    except kind as e:
        return str(e)
    except Exception as e:  # noqa: BLE001
        return "%s: %s" % (type(e).__name__, e)
    return ""


def image_of(values, first_voxel=(0, 0, 0), name="data"):
    """A vtkImageData of values [z, y, x] (components last) whose extent starts at
    first_voxel (x, y, z)."""
    image = vtkImageData()
    nz, ny, nx = values.shape[:3]
    x0, y0, z0 = first_voxel
    image.SetExtent(x0, x0 + nx - 1, y0, y0 + ny - 1, z0, z0 + nz - 1)
    scalars = numpy_to_vtk(values.reshape(nx * ny * nz, -1) if values.ndim == 4 else values.reshape(-1), deep=1)
    scalars.SetName(name)
    image.GetPointData().SetScalars(scalars)
    return image


rng = np.random.default_rng(60)
shape = (20, 30, 40)                                   # [z, y, x]: no two axes alike
smooth = np.cumsum(np.cumsum(rng.normal(size=shape), axis=0), axis=2).astype(np.float32)
level = float(np.median(smooth))
vertices = np.array([[10.0, 15.0, 20.0], [4.0, 9.0, 31.0]])     # (z, y, x), inside
ao = volumetricao.ambient_occlusion(smooth, radius=2)

# 1. NaN and infinite voxels: the first in C order, by its numpy index. Planted at [1, 2, 3]
# and at [2, 1, 0], which comes first in x-fastest order read backwards (VTK's voxel 0, 1, 2).
planted = smooth.copy()
planted[1, 2, 3] = np.nan
planted[2, 1, 0] = np.inf
functions = {
    "ambient_occlusion": lambda v: volumetricao.ambient_occlusion(v, radius=2),
    "ambient_occlusion (Gaussian CDF)": lambda v: volumetricao.ambient_occlusion(v, radius=2, method="gaussian cdf"),
    "occlusion_sweeping": lambda v: volumetricao.occlusion_sweeping(v, level),
    "variance_occlusion_map": lambda v: volumetricao.variance_occlusion_map(v),
    "isosurface_ambient_occlusion": lambda v: volumetricao.isosurface_ambient_occlusion(v, vertices),
    "shade (values)": lambda v: volumetricao.shade(v, ao),
    "shade (ao)": lambda v: volumetricao.shade(smooth, v),
}
for name, call in functions.items():
    for form, volume in (("numpy", planted), ("a vtkImageData whose extent starts at (5, 6, 7)",
                                             image_of(planted, (5, 6, 7)))):
        if name == "shade (ao)" and form != "numpy":
            continue
        text = error_of(lambda: call(volume))
        check("at index [1, 2, 3] (z, y, x)" in text and "2 NaN or infinite values" in text
              and "first in C order" in text and "np.nan_to_num" in text and "3, 2, 1" not in text
              and not VTK_WORDS.search(text),
              "%s, %s: a NaN at [1, 2, 3] and an infinity at [2, 1, 0] are named by the first's numpy index: %s"
              % (name, form, text[:120]))
values = rng.normal(size=5)
values[3] = np.nan
text = error_of(lambda: volumetricao.shade(values, np.ones(5)))
check("at index [3] (vertex)" in text and not VTK_WORDS.search(text),
      "shade of vertices: a NaN value is named by its vertex: %s" % text[:100])
text = error_of(lambda: volumetricao.shade(None, np.ones(5), shadow=values))
check("shadow has 1 NaN" in text and "[3] (vertex)" in text, "shade of vertices: a NaN shadow too: %s" % text[:80])

# A 4-D array: only the component the filter reads is refused, and named with it.
stacked = np.stack([planted, smooth], axis=-1)
text = error_of(lambda: volumetricao.ambient_occlusion(stacked, radius=2, component=0))
check("at index [1, 2, 3, 0] (z, y, x, component)" in text, "a 4-D array: the NaN named with its component: %s"
      % text[:90])
check(same(volumetricao.ambient_occlusion(stacked, radius=2, component=1), ao),
      "a 4-D array whose other component has NaN: accepted, as the filter accepts it")
for component, words in ((None, "got None"), (2, "got 2")):
    text = error_of(lambda: volumetricao.ambient_occlusion(stacked, radius=2, component=component))
    check("2 components" in text and "pass component, one of 0..1" in text and words in text
          and not VTK_WORDS.search(text), "component=%r of 2: %s" % (component, text[:90]))
text = error_of(lambda: volumetricao.ambient_occlusion(image_of(np.stack([smooth, smooth], -1)), radius=2))
check("pass component, one of 0..1 (got None)" in text and not VTK_WORDS.search(text),
      "a vtkImageData of 2 components without component: %s" % text[:90])

# 2. Shapes in numpy's order.
for name, call in (("ambient_occlusion", lambda v: volumetricao.ambient_occlusion(v, radius=1)),
                   ("occlusion_sweeping", lambda v: volumetricao.occlusion_sweeping(v, level)),
                   ("variance_occlusion_map", lambda v: volumetricao.variance_occlusion_map(v)),
                   ("isosurface_ambient_occlusion",
                    lambda v: volumetricao.isosurface_ambient_occlusion(v, np.zeros((0, 3))))):
    for thin in (smooth[:1], smooth[:, :1], smooth[:, :, :0]):
        expected = "got shape %s (z, y, x)" % (thin.shape,)
        for form, volume in (("numpy", thin), ("vtkImageData", image_of(thin))):
            text = error_of(lambda: call(volume))
            check(expected in text and "needs a 3-D volume" in text,
                  "%s of shape %s (%s): %s" % (name, thin.shape, form, text[:100]))
for form, volume in (("numpy", smooth), ("vtkImageData", image_of(smooth))):
    text = error_of(lambda: volumetricao.ambient_occlusion(volume, radius=100))
    check("covers the whole volume of shape (20, 30, 40)" in text and "40 x 30 x 20" not in text,
          "a radius over the whole (20, 30, 40) volume (%s): %s" % (form, text[:110]))
text = error_of(lambda: volumetricao.ambient_occlusion(smooth, radius=2.0, world_radius=True, sampling=(1, 1, 0)))
check("the sampling (z, y, x) is (1, 1, 0)" in text and not VTK_WORDS.search(text),
      "a world radius with a zero sampling of axis 2: %s" % text[:120])
text = error_of(lambda: volumetricao.occlusion_sweeping(smooth, level, sampling=(1, 1, 0)))
check("sampling must be finite and positive (got (1, 1, 0) for (z, y, x))" in text,
      "occlusion_sweeping with a zero sampling of axis 2: %s" % text[:110])

# 3. Vertices outside the volume: the numpy axis, the vertex and its coordinate.
for axis in range(3):
    outside = vertices.copy()
    outside[1, axis] = shape[axis] + 5.0
    for form, volume in (("numpy", smooth), ("vtkImageData", image_of(smooth))):
        text = error_of(lambda: volumetricao.isosurface_ambient_occlusion(volume, outside))
        named = ("vertex 1 (row 1 of vertices) lies at %g along axis %d" % (shape[axis] + 5, axis) if form == "numpy"
                 else "axis %d of the volume" % axis)
        check("The surface reaches outside the volume" in text and named in text
              and ("axis %d" % (2 - axis) not in text or axis == 1),
              "a vertex outside along numpy axis %d (%s): %s" % (axis, form, text[:130]))
text = error_of(lambda: volumetricao.isosurface_ambient_occlusion(smooth, [[1.0, np.nan, 2.0]]))
check("vertex 0 (row 0) is not finite" in text, "a NaN vertex: %s" % text[:80])
flat = np.zeros(shape, np.float32)
flat[10:] = 1
text = error_of(lambda: volumetricao.isosurface_ambient_occlusion(flat, [[3.0, 4.0, 5.0]]))
check(("Vertex 0" in text or "vertex 0" in text) and "normals" in text and not VTK_WORDS.search(text),
      "a vertex where the gradient is zero, without normals: %s" % text[:120])

# ... refused exactly where the filter refuses them: at the limits of half a voxel, on the
# same doubles (float64 vertices, and float32 ones as VTK reads them).
sampling = (2.0, 0.5, 1.25)
image = image_of(smooth)
image.SetSpacing(*reversed(sampling))


def filter_refuses(points_zyx):
    """Whether vtkIsosurfaceAmbientOcclusion itself reports the surface outside."""
    surface = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(points_zyx[:, ::-1]), deep=1))
    surface.SetPoints(points)
    normals = numpy_to_vtk(np.tile([1.0, 0.0, 0.0], (len(points_zyx), 1)), deep=1)
    normals.SetName("Normals")
    surface.GetPointData().SetNormals(normals)
    iso = volumetricao.vtkIsosurfaceAmbientOcclusion()
    iso.SetController(None)
    iso.SetInputData(surface)
    iso.SetVolumeData(image)
    messages = []
    iso.AddObserver(vtkCommand.ErrorEvent, lambda caller, event: messages.append(event))
    iso.GetExecutive().AddObserver(vtkCommand.ErrorEvent, lambda caller, event: messages.append(event))
    iso.Update()
    return iso.GetOutput().GetNumberOfPoints() == 0


agreed = []
for axis in range(3):
    top = (shape[axis] - 1) * sampling[axis]
    for limit in (-0.5 * sampling[axis], top + 0.5 * sampling[axis]):
        for coordinate in (limit, np.nextafter(limit, -np.inf), np.nextafter(limit, np.inf)):
            for dtype in (np.float64, np.float32):
                point = vertices[:1].astype(dtype)
                point[0, axis] = coordinate
                raised = "reaches outside" in error_of(lambda: volumetricao.isosurface_ambient_occlusion(
                    smooth, point, np.tile([1.0, 0.0, 0.0], (1, 1)), sampling=sampling))
                agreed.append(raised == filter_refuses(point.astype(np.float64)))
check(len(agreed) == 36 and all(agreed),
      "vertices at and beside the limits of half a voxel: refused exactly where the filter refuses them "
      "(%d of %d agree)" % (sum(agreed), len(agreed)))

# The light, in (z, y, x); a zero one refused only when shadows are asked for.
text = error_of(lambda: volumetricao.isosurface_ambient_occlusion(smooth, vertices, shadows=True,
                                                                  light_direction=(0.0, 0.0, 0.0)))
check("light_direction" in text and "(z, y, x)" in text and not VTK_WORDS.search(text),
      "a zero light_direction with shadows: %s" % text[:100])
check(volumetricao.isosurface_ambient_occlusion(smooth, vertices, light_direction=(0.0, 0.0, 0.0)).shape == (2,),
      "a zero light_direction without shadows: accepted, as the filter accepts it")

# Every filter message that names VTK's axes or ParaView's filters, translated (those a
# numpy array cannot reach too: the wording is the filters').
translated = [
    ("Array 'a' has 3 NaN or infinite values (the first at voxel 3, 2, 1). A non-finite value has no place in a "
     "cumulative distribution or an isosurface: replace them (e.g. with the Calculator or Threshold filters) first.",
     "the first in C order at index [1, 2, 3] (z, y, x)"),
    ("Array 'a' has NaN or infinite values (the first at point 1283): replace them (e.g. with the Calculator or "
     "Threshold filters) first.", "index [1, 2, 3]"),
    ("Histogram CDF's value histogram failed: the volume has 1 non-finite value (NaN or infinity), the first at "
     "voxel index 1283.", "index [1, 2, 3]"),
    ("The filter needs a 3-D volume; the input is 40 x 30 x 1 voxels (empty, a single voxel, or 2-D).",
     "got shape (1, 30, 40) (z, y, x)"),
    ("Ambient occlusion failed: the method needs a 3-D volume with at least 2 voxels per axis (got 40 x 30 x 1).",
     "shape (1, 30, 40)"),
    ("Radius 5 (world units) (5 x 3 x 1 voxels) covers the whole 6 x 4 x 2 volume from every voxel",
     "(1, 3, 5 voxels along axes 0, 1, 2) covers the whole volume of shape (2, 4, 6)"),
    ("Occlusion sweeping failed: occlusion sweeping needs spacings between 1e-10 and 1e+10 (its distances are "
     "float; got 1e-20, 1, 2): rescale the volume (e.g. with Change Spacing).", "got (2, 1, 1e-20) for (z, y, x)"),
    ("The variance occlusion map failed: the origin must be finite (got nan, 1, 2).", "(2, 1, nan) for (z, y, x)"),
    ("LightDirection must be finite (got nan, 0, 1).", "light_direction must be finite (got (1, 0, nan)"),
    ("The surface reaches outside the volume (axis 2: surface 10..25, volume 0..19): give the volume the surface was "
     "extracted from.", "(axis 0 of the volume"),
    ("the output region [0, 50) of axis 0 is empty or outside the volume's 40 voxels", "of axis 2 (z, y, x)"),
    ("The surface has no point normals and the volume's gradient is zero at point 7: add normals (e.g. Contour with "
     "Compute Normals, or Generate Surface Normals).", "vertex 7"),
    ("Isosurface ambient occlusion failed: non-finite normal at point 4.", "at vertex 4 (row 4 of normals)"),
    ("Ambient occlusion failed: the values reach 1e+200 in magnitude; above 1e+140 their squared sums overflow double "
     "precision: rescale the data (e.g. with the Calculator) first.", "array / np.abs(array).max()"),
    ("The values lie far from 0 against their spread: the pyramid's float32 means resolve 0.01 of it (above 0.0001), "
     "so AO and shadows lose precision. Subtract an offset first (e.g. with the Calculator).", "array - array.mean()"),
]
for message, words in translated:
    image = image_of(np.zeros(shape, np.float32))
    text = _common.numpy_terms(message, image)
    check(words in text and not VTK_WORDS.search(text) and not re.search(r"\d+ x \d+ x \d+", text),
          "translated: %s -> %s" % (message[:50], text[:110]))

# 4. Types: every numeric argument of the five functions refuses a string, bytes and a bool
# with a TypeError naming it; every integer argument a float, as threads does.
small = smooth[:8, :9, :10]
calls = {
    "ambient_occlusion": lambda **k: volumetricao.ambient_occlusion(small, **dict({"radius": 2}, **k)),
    "occlusion_sweeping": lambda **k: volumetricao.occlusion_sweeping(small, **dict({"iso_value": level}, **k)),
    "variance_occlusion_map": lambda **k: volumetricao.variance_occlusion_map(small, **k),
    "isosurface_ambient_occlusion": lambda **k: volumetricao.isosurface_ambient_occlusion(small, [[3.0, 4.0, 5.0]],
                                                                                          **k),
    "shade": lambda **k: volumetricao.shade(small, np.ones_like(small), **k),
}
numeric = {
    "ambient_occlusion": {"radius": 2.0, "iso_value": 0.0, "query_smoothing": 1.0, "number_of_bins": 16,
                          "threads": 1, "device": 0, "component": 0, "sampling": 1.0},
    "occlusion_sweeping": {"iso_value": level, "iterations": 2, "tolerance": 0.1, "gamma": 2.0, "opacity": 0.5,
                           "threads": 1, "component": 0, "sampling": 1.0},
    "variance_occlusion_map": {"levels": 2, "threads": 1, "component": 0, "sampling": 1.0},
    "isosurface_ambient_occlusion": {"iso_value": 0.0, "levels": 2, "offset_factor": 0.5, "threads": 1,
                                     "component": 0, "sampling": 1.0, "light_direction": (1.0, 0.0, 0.0)},
    "shade": {"ambient_intensity": 0.5, "gamma": 2.0, "variance_max": 1.0, "threads": 1, "sampling": 1.0,
              "scalar_range": (0.0, 1.0), "opacity_ramp": (0.0, 1.0)},
}
for function, arguments in numeric.items():
    call = calls[function]
    for argument, good in arguments.items():
        integer = isinstance(good, int)
        sequence = isinstance(good, tuple)
        wrong = [str(good), repr(good).encode(), True]
        wrong = [tuple(str(v) for v in good), (True,) + good[1:], str(good)] if sequence else wrong
        wrong += [good + 0.5] if integer else []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            call(**{argument: good})                     # the right kind runs
            texts = [error_of(lambda: call(**{argument: bad}), TypeError) for bad in wrong]
        check(all(argument in text and not text.startswith(("ValueError", "RuntimeError")) for text in texts),
              "%s(%s=...) refuses %s with a TypeError naming it: %s"
              % (function, argument, ", ".join(repr(w) for w in wrong), texts[0][:60]))
text = error_of(lambda: volumetricao.ambient_occlusion(small, radius="5"), TypeError)
check(text == "radius must be a real number, got '5'", "radius='5': %s" % text)
text = error_of(lambda: volumetricao.ambient_occlusion(small, radius=2, threads=1.5), TypeError)
check(text == "threads must be an integer, got 1.5", "threads=1.5: %s" % text)
check(error_of(lambda: volumetricao.occlusion_sweeping(small, level, octant_mask="01010101"), TypeError)
      .startswith("octant_mask"), "octant_mask as a string (each character would be True) raises TypeError")
check(error_of(lambda: volumetricao.ambient_occlusion(small, method="transfer function", opacity=[("0", 0)]),
               TypeError).startswith("opacity"), "opacity points as strings raise TypeError")
reference = volumetricao.ambient_occlusion(small, radius=2, threads=2, number_of_bins=16)
check(all(same(volumetricao.ambient_occlusion(small, radius=r, threads=t, number_of_bins=b), reference)
          for r, t, b in ((np.float32(2), np.int64(2), np.int16(16)), (np.array(2.0), np.array(2), np.uint8(16)),
                          (2, 2, 16))),
      "numpy scalars and 0-d arrays are numbers like Python's")

finish("all numpy-terms checks passed")
