"""What the numpy functions share: reading their arguments the scipy way, building the
vtkImageData, running a filter with Python's errors, warnings and progress, and the
report of what ran."""
import collections
import operator
import re
import sys
import warnings

import numpy as np

from vtkmodules.util.misc import calldata_type
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_STRING
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkImageData, vtkPiecewiseFunction
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm, vtkAlgorithmOutput


class VolumetricAOWarning(UserWarning):
    """A warning of a VolumetricAO filter (or of the numpy functions about one), e.g. an
    iso value that crosses no voxel, or CUDA asked for where the CPU ran.

    Filter it like any warning: ``warnings.simplefilter("ignore", VolumetricAOWarning)``.
    """


RunInfo = collections.namedtuple("RunInfo", ["backend", "device", "threads"])
RunInfo.__doc__ = """What ran, returned with ``return_info=True``.

backend: "CPU" or "CUDA". device: the CUDA device ("CPU" when the CPU ran). threads: the
CPU threads the filter used, where it reports them (Volumetric AO), else None."""

_BACKENDS = ("auto", "cpu", "cuda")

# VTK's decoration of a filter's message: "ERROR: In file.cxx, line N\n" and
# "vtkClass (0x55d...): ".
_LOCATION = re.compile(r"^(?:ERROR|Warning|Generic Warning|Debug): In [^\n]*, line \d+\n", re.M)
_OBJECT = re.compile(r"^vtk\w+ \(0x[0-9a-fA-F]+\): ", re.M)
# Messages of a computation that could not be done (memory, a device, another MPI
# process, an abort), as opposed to arguments or data the filter refuses: those say
# "... failed: <the argument's problem>" too.
_FAILURE = re.compile(r"memory|CUDA|device|another process|abort", re.I)


def filter_sentence(message):
    """The filter's own sentence from a VTK error or warning text."""
    return _OBJECT.sub("", _LOCATION.sub("", str(message))).strip()


def choice(value, table, what):
    """table[value], the key spelt in any case and with _ for spaces; else a ValueError
    that lists the choices."""
    key = str(value).lower().replace("_", " ")
    if key not in table:
        raise ValueError("unknown %s %r (one of %s)" % (what, value, ", ".join(repr(k) for k in table)))
    return table[key]


def check_backend(backend):
    key = str(backend).lower()
    if key not in _BACKENDS:
        raise ValueError("backend must be 'auto', 'cpu' or 'cuda', got %r" % (backend,))
    return key


def check_threads(threads):
    return number(threads, "threads", integer=True)


# What no numeric argument takes, though float() or int() would: float("5") reads a
# string, True is 1, and float() of a complex number drops its imaginary part.
_NOT_NUMBERS = (str, bytes, bytearray, memoryview, bool, np.bool_, complex, np.complexfloating, np.ndarray)


def number(value, name, integer=False):
    """The one check of every numeric argument: a float (an int with integer=True), or
    TypeError naming the argument. A real number is taken (Python's, numpy's, a 0-d
    array); strings, bytes, bools and complex numbers are refused, and an integer argument
    refuses floats, 2.0 included, as numpy does for a shape (operator.index)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if not isinstance(value, _NOT_NUMBERS):
        try:
            return operator.index(value) if integer else float(value)
        except (TypeError, ValueError):
            pass
    raise TypeError("%s must be %s, got %r" % (name, "an integer" if integer else "a real number", value))


def numbers(value, name):
    """A float64 array of value's shape from a number or a sequence or array of them,
    each checked as number() checks one (a numeric array at once)."""
    if isinstance(value, np.ndarray) and value.dtype.kind in "iuf":
        return value.astype(np.float64)
    try:
        items = np.asarray(value, dtype=object)
        return np.array([number(v, name) for v in items.reshape(-1)], dtype=np.float64).reshape(items.shape)
    except (TypeError, ValueError):
        raise TypeError("%s: real numbers expected, got %r" % (name, value)) from None


def flags(value, name, count):
    """`count` booleans (or 0 and 1) as ints; TypeError for strings ("0" would be True)."""
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":
        raise TypeError("%s: %d flags (bools or 0 and 1) expected, got %r" % (name, count, value))
    result = [int(bool(v)) for v in array.reshape(-1)]
    if len(result) != count:
        raise ValueError("%s: %d flags, got %d" % (name, count, len(result)))
    return result


def opacity_function(opacity, name="opacity"):
    """A vtkPiecewiseFunction from one, from a ParaView opacity transfer function
    (``GetOpacityTransferFunction(array)``: its object is used, so later edits count), or
    from points: an (N, 2) array of (value, opacity), an (N, 4) array of (value, opacity,
    midpoint, sharpness), or a flat list in ParaView's ``Points`` order (value, opacity,
    midpoint, sharpness, ...). Points make a clamped function, as VTK's default."""
    if isinstance(opacity, vtkPiecewiseFunction):
        return opacity
    if hasattr(opacity, "GetClientSideObject"):
        function = opacity.GetClientSideObject()
        if not isinstance(function, vtkPiecewiseFunction):
            raise TypeError("%s: %r is not an opacity (piecewise) transfer function" % (name, opacity))
        if _untouched(opacity):
            raise ValueError(
                "%s: this opacity transfer function was never fitted to any data: ParaView makes it as a step "
                "from 0 at 0 to 1 at 1, in the array's units, and fits it to the data's range when something is "
                "coloured by the array. Fit it first, e.g. function.RescaleTransferFunction(volume.min(), "
                "volume.max()), or pass (value, opacity) points" % name)
        return function
    try:
        points = numbers(opacity, name)
    except TypeError:
        raise TypeError("%s: a vtkPiecewiseFunction or (value, opacity) points, got %r" % (name, opacity)) from None
    if points.ndim == 1 and points.size % 4 == 0 and points.size > 0:
        points = points.reshape(-1, 4)
    if points.ndim != 2 or points.shape[1] not in (2, 4) or points.shape[0] == 0:
        raise ValueError("%s: (N, 2) points (value, opacity) or (N, 4) (value, opacity, midpoint, sharpness), "
                         "got shape %s" % (name, points.shape))
    # Before VTK sorts them: the filters check the rest of the function (its opacities).
    if not np.isfinite(points).all():
        raise ValueError("%s: the points must be finite (no NaN or infinity)" % name)
    function = vtkPiecewiseFunction()
    function.AllowDuplicateScalarsOn()
    for row in points:
        if points.shape[1] == 4:
            function.AddPoint(row[0], row[1], row[2], row[3])
        else:
            function.AddPoint(row[0], row[1])
    return function


def _untouched(proxy):
    """Whether a ParaView opacity transfer function is the one ParaView made and never
    fitted: points (0, 0) and (1, 1), its range never initialised."""
    try:
        return (int(proxy.GetPropertyValue("ScalarRangeInitialized")) == 0
                and [float(v) for v in proxy.GetPropertyValue("Points")] == [0.0, 0.0, 0.5, 0.0, 1.0, 1.0, 0.5, 0.0])
    except (AttributeError, TypeError, ValueError):
        return False


def three(value, name):
    """Three floats from a scalar or a sequence of three."""
    values = numbers(value, name).reshape(-1)
    if values.size == 1:
        values = np.repeat(values, 3)
    if values.size != 3:
        raise ValueError("%s: one value, or one per array axis (3), got %d" % (name, values.size))
    return tuple(float(v) for v in values)


def pair(value, name):
    """Two floats (low, high)."""
    values = numbers(value, name).reshape(-1)
    if values.size != 2:
        raise ValueError("%s: two values (low, high), got %d" % (name, values.size))
    return float(values[0]), float(values[1])


def readable(array, name="volume"):
    """The array as VTK can read it: C order, native byte order, a type VTK has (no copy
    when it already is)."""
    if isinstance(array, (str, bytes, dict)) or array is None:
        raise TypeError("%s: expected a numpy array or a vtkImageData, got %s" % (name, type(array).__name__))
    values = np.ascontiguousarray(array)
    kind = values.dtype.kind
    if kind == "c":
        raise ValueError("complex values have no order to rank: pass the real part or the magnitude")
    if kind not in "biuf":
        raise ValueError("expected a numeric array, got dtype %s" % values.dtype)
    if kind == "b":
        return values.view(np.uint8)
    if values.dtype == np.float16:
        return values.astype(np.float32)
    # VTK reads the bytes in the machine's order: another order would be silently wrong.
    return values.astype(values.dtype.newbyteorder("="), copy=False)


def vtk_array(values, name):
    """A VTK array over the contiguous numpy array `values` (no copy; it keeps them alive)."""
    result = numpy_to_vtk(values if values.ndim == 2 else values.reshape(-1), deep=0)
    result.SetName(name)
    return result


def image_data(volume):
    """The vtkImageData behind `volume` (itself, or an algorithm's output), else None."""
    if isinstance(volume, vtkAlgorithmOutput):
        producer = volume.GetProducer()
        producer.Update(volume.GetIndex())
        volume = producer.GetOutputDataObject(volume.GetIndex())
    elif isinstance(volume, vtkAlgorithm):
        volume.Update()
        volume = volume.GetOutputDataObject(0)
    if isinstance(volume, vtkDataObject):
        if not isinstance(volume, vtkImageData):
            raise TypeError("expected image data, got a %s" % volume.GetClassName())
        return volume
    return None


Volume = collections.namedtuple("Volume", ["image", "shape", "keep"])


def volume_image(volume, sampling=None, spacing=None, what="volume", stacklevel=3):
    """The volume as a vtkImageData: a numpy array [z, y, x] (or [z, y, x, component])
    with `sampling` per array axis, or a vtkImageData (shallow-copied, its spacing, origin
    and direction kept). `spacing` is the deprecated (x, y, z) form of `sampling`."""
    if spacing is not None:
        if sampling is not None:
            raise TypeError("give sampling or spacing, not both")
        warnings.warn("spacing (x, y, z) is deprecated and will be removed after 0.3: give sampling, one value per array axis "
                      "[z, y, x] as scipy.ndimage takes it (sampling=spacing[::-1])", DeprecationWarning,
                      stacklevel=stacklevel)
        sampling = tuple(reversed(three(spacing, "spacing")))
    given = image_data(volume)
    if given is not None:
        if sampling is not None:
            raise TypeError("a vtkImageData carries its own spacing: leave sampling out")
        image = vtkImageData()
        image.ShallowCopy(given)
        nx, ny, nz = image.GetDimensions()
        return Volume(image, (nz, ny, nx), None)
    values = readable(volume, what)
    if values.ndim not in (3, 4):
        raise ValueError("expected a 3-D array indexed [z, y, x] (or 4-D, [z, y, x, component]), got shape %s"
                         % (values.shape,))
    z, y, x = three(1.0 if sampling is None else sampling, "sampling")
    image = vtkImageData()
    image.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    image.SetSpacing(x, y, z)
    components = values.shape[3] if values.ndim == 4 else 1
    scalars = numpy_to_vtk(values.reshape(-1, components) if components > 1 else values.reshape(-1), deep=0)
    scalars.SetName("Scalars")
    image.GetPointData().SetScalars(scalars)
    return Volume(image, values.shape[:3], values)


def choose_scalars(algorithm, scalars, port=0):
    """Process the point array named `scalars` (None: the active scalars)."""
    if scalars is not None:
        algorithm.SetInputArrayToProcess(0, port, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, str(scalars))


def set_component(algorithm, component):
    if component is not None:
        algorithm.SetComponent(number(component, "component", integer=True))


# Why the filters refuse non-finite values, in their words.
IN_A_VOLUME = "a non-finite value has no place in a cumulative distribution or an isosurface"
IN_COLOURS = "they have no colour, opacity or shade"
_AXES = {1: "vertex", 3: "z, y, x", 4: "z, y, x, component"}


def non_finite(values):
    """(count, index): how many NaN and infinite values `values` holds, and the index of
    the first in C order (None when there is none; integer arrays have none). Read in
    blocks along the first axis, so that a finite volume costs no mask of its size."""
    if values.dtype.kind != "f" or values.size == 0:
        return 0, None
    step = max(1, (1 << 22) // max(1, values.size // values.shape[0]))
    count, first = 0, None
    for start in range(0, values.shape[0], step):
        bad = ~np.isfinite(values[start:start + step])
        found = int(np.count_nonzero(bad))
        if found and first is None:
            first = tuple(int(i) for i in np.unravel_index(np.argmax(bad), bad.shape))
            first = (first[0] + start,) + first[1:]
        count += found
    return count, first


def non_finite_sentence(what, count, index, reason, name="array"):
    """The message for `count` non-finite values of `what`, the first at numpy `index`."""
    return ("%s has %d NaN or infinite value%s, the first in C order at index [%s] (%s): %s. Replace them "
            "first, e.g. with np.nan_to_num(%s, nan=0.0, posinf=high, neginf=low), or through a mask: "
            "%s[~np.isfinite(%s)] = value"
            % (what, count, "" if count == 1 else "s", ", ".join(str(i) for i in index),
               _AXES.get(len(index), "index"), reason, name, name, name))


def check_finite(values, name, reason):
    """ValueError naming the first non-finite value of the numpy array `values` (given as
    argument `name`) by its numpy index."""
    count, first = non_finite(values)
    if count:
        raise ValueError(non_finite_sentence(name, count, first, reason, name))


def check_volume(volume, component, name):
    """What every volume filter refuses, said in numpy's terms before it runs: fewer than 2
    voxels along an axis, a component the array does not have, NaN or infinite values
    (the filters name voxels in VTK's (x, y, z) order). A vtkImageData's values are left to
    the filter, whose message numpy_terms translates."""
    if min(volume.shape) < 2:
        raise ValueError("%s: the filter needs a 3-D volume, at least 2 voxels along every axis; got shape %s "
                         "(z, y, x)" % (name, tuple(int(n) for n in volume.shape)))
    values = volume.keep
    if values is None:
        return
    components = values.shape[3] if values.ndim == 4 else 1
    picked = -1 if component is None else number(component, "component", integer=True)
    picked = 0 if picked < 0 and components == 1 else picked
    if not 0 <= picked < components:
        raise ValueError("%s has %d component%s (axis 3 of [z, y, x, component]): pass component, one of 0..%d "
                         "(got %r)" % (name, components, "" if components == 1 else "s", components - 1, component))
    if values.ndim == 4:
        # In place: the column the filter reads; the index names it as the fourth.
        count, first = non_finite(values[..., picked])
        if count:
            raise ValueError(non_finite_sentence(name, count, first + (picked,), IN_A_VOLUME, name))
    else:
        check_finite(values, name, IN_A_VOLUME)


def _reversed(match, first=1):
    """The three numbers of groups first..first+2, in (z, y, x) order."""
    return "(%s, %s, %s)" % (match.group(first + 2), match.group(first + 1), match.group(first))


def _voxel_index(match, image, x=3):
    """Groups x, x+1, x+2 (a voxel of the image's extent, x first) as a numpy index."""
    start = image.GetExtent()[::2] if image is not None else (0, 0, 0)
    return tuple(int(match.group(x + a)) - start[a] for a in (2, 1, 0))


def _point_index(point, image, vertices):
    """A filter's point id as a numpy index: a vertex's row, or a voxel [z, y, x]."""
    if vertices or image is None:
        return (point,)
    nx, ny, nz = image.GetDimensions()
    return tuple(int(i) for i in np.unravel_index(point, (nz, ny, nx)))


_NUMBER = r"([^\s,()]+)"
_ADVICE = r" \(e\.g\. with the Calculator or Threshold filters\)"
# The filters' messages that name voxels, shapes, axes or spacings in VTK's (x, y, z) order,
# or ParaView's filters as the remedy, and what the numpy functions say instead. Each is
# (pattern, replacement(match, image, vertices)); the specific ones come first.
_TRANSLATIONS = [(re.compile(pattern), replacement) for pattern, replacement in [
    (r"Array '([^']*)' has (\d+) NaN or infinite values \(the first at voxel (-?\d+), (-?\d+), (-?\d+)\)\. "
     r"A non-finite value has no place in a cumulative distribution or an isosurface: replace them" + _ADVICE +
     r" first\.",
     lambda m, image, vertices: non_finite_sentence("array '%s'" % m.group(1), int(m.group(2)),
                                                    _voxel_index(m, image), IN_A_VOLUME)),
    (r"Array '([^']*)' has (\d+) NaN or infinite values \(the first at point (\d+)\): they have no colour, "
     r"opacity or shade; replace them" + _ADVICE + r" first\.",
     lambda m, image, vertices: non_finite_sentence("array '%s'" % m.group(1), int(m.group(2)),
                                                    _point_index(int(m.group(3)), image, vertices), IN_COLOURS)),
    (r"\(the first at voxel (-?\d+), (-?\d+), (-?\d+)\)",
     lambda m, image, vertices: "(the first in C order at index [%d, %d, %d] (z, y, x))" % _voxel_index(m, image, 1)),
    (r"\(the first at point (\d+)\)",
     lambda m, image, vertices: "(the first in C order at index [%s])"
     % ", ".join(str(i) for i in _point_index(int(m.group(1)), image, vertices))),
    (r"the first at voxel index (\d+)",
     lambda m, image, vertices: "the first in C order at index [%s]"
     % ", ".join(str(i) for i in _point_index(int(m.group(1)), image, False))),
    (r"replace them" + _ADVICE + r" first",
     lambda m, image, vertices: "replace them first, e.g. with np.nan_to_num(array, nan=0.0, posinf=high, "
                                "neginf=low), or through a mask: array[~np.isfinite(array)] = value"),
    (r"(overflow double precision\)?): rescale the data \(e\.g\. with the Calculator\) first",
     lambda m, image, vertices: m.group(1) + ": rescale the array first, e.g. array / np.abs(array).max()"),
    (r"rescale the data \(e\.g\. with the Calculator\) first",
     lambda m, image, vertices: "rescale the array first, e.g. (array - array.min()) / np.ptp(array)"),
    (r"Subtract an offset first \(e\.g\. with the Calculator\)",
     lambda m, image, vertices: "Subtract an offset first (e.g. array - array.mean())"),
    (r"Radius " + _NUMBER + r"( \(world units\))? \((\d+) x (\d+) x (\d+) voxels\) covers the whole "
     r"(\d+) x (\d+) x (\d+) volume",
     lambda m, image, vertices: "Radius %s%s (%s, %s, %s voxels along axes 0, 1, 2) covers the whole volume of "
                                "shape %s" % (m.group(1), m.group(2) or "", m.group(5), m.group(4), m.group(3),
                                              _reversed(m, 6))),
    (r"The filter needs a 3-D volume; the input is (\d+) x (\d+) x (\d+) voxels \(empty, a single voxel, or 2-D\)",
     lambda m, image, vertices: "The filter needs a 3-D volume, at least 2 voxels along every axis; got shape %s "
                                "(z, y, x)" % _reversed(m)),
    (r"(-?\d+) x (-?\d+) x (-?\d+)( voxels)?",
     lambda m, image, vertices: "shape %s (z, y, x)" % _reversed(m)),
    (r"the input's is " + _NUMBER + ", " + _NUMBER + ", " + _NUMBER + r"\. Fix the spacing \(e\.g\. with Change "
     r"Spacing\) or give the radius in voxels",
     lambda m, image, vertices: "the sampling (z, y, x) is %s: give a finite, positive sampling, or the radius in "
                                "voxels (world_radius=False)" % _reversed(m)),
    (r"occlusion sweeping needs spacings between " + _NUMBER + " and " + _NUMBER + r" \(its distances are float; "
     r"got " + _NUMBER + ", " + _NUMBER + ", " + _NUMBER + r"\): rescale the volume \(e\.g\. with Change Spacing\)",
     lambda m, image, vertices: "occlusion sweeping needs a sampling between %s and %s on every axis (its distances "
                                "are float; got %s for (z, y, x)): give the sampling in other units"
     % (m.group(1), m.group(2), _reversed(m, 3))),
    (r"(?:the )?spacing must be finite and positive \(got " + _NUMBER + ", " + _NUMBER + ", " + _NUMBER + r"\)",
     lambda m, image, vertices: "the sampling must be finite and positive (got %s for (z, y, x))" % _reversed(m)),
    (r"the origin must be finite \(got " + _NUMBER + ", " + _NUMBER + ", " + _NUMBER + r"\)",
     lambda m, image, vertices: "the origin must be finite (got %s for (z, y, x))" % _reversed(m)),
    (r"LightDirection must be (finite|a non-zero vector of finite length) \(got " + _NUMBER + ", " + _NUMBER + ", "
     + _NUMBER + r"\)",
     lambda m, image, vertices: "light_direction must be %s (got %s for (z, y, x))" % (m.group(1), _reversed(m, 2))),
    (r"\(axis (\d): surface ",
     lambda m, image, vertices: "(axis %d of the volume [z, y, x] and of the vertices (z, y, x): surface "
     % (2 - int(m.group(1)))),
    (r"\b(of|on) axis (\d)\b",
     lambda m, image, vertices: "%s axis %d (z, y, x)" % (m.group(1), 2 - int(m.group(2)))),
    (r"The surface has no point normals and the volume's gradient is zero at point (\d+): add normals "
     r"\(e\.g\. Contour with Compute Normals, or Generate Surface Normals\)",
     lambda m, image, vertices: "The volume's gradient is zero at vertex %s, so it gives that vertex no normal: "
                                "pass normals ((N, 3), (z, y, x) order, towards lower values), or leave the vertex "
                                "out" % m.group(1)),
    (r"Point (\d+) of the surface has (no normal|a zero or non-finite normal), the volume's gradient is zero there "
     r"and it has no polygon with an area: remove it \(e\.g\. Clean\), or give it a normal",
     lambda m, image, vertices: "Vertex %s has %s and the volume's gradient is zero there: pass normals with a "
                                "usable row %s ((N, 3), (z, y, x) order, towards lower values), or leave the vertex "
                                "out" % (m.group(1), "no normal (normals=None)" if m.group(2) == "no normal"
                                         else "a zero or non-finite normal (row %s of normals)" % m.group(1),
                                         m.group(1))),
    (r"(non-finite coordinate|non-finite normal|zero normal) at point (\d+)",
     lambda m, image, vertices: "%s at vertex %s (row %s of %s)" % (m.group(1), m.group(2), m.group(2),
                                                                   "vertices" if "coordinate" in m.group(1)
                                                                   else "normals")),
    (r"(\d+) of the surface's (\d+) point normals are zero or not finite: those points take the volume's "
     r"gradient \(or their polygons' normal\) instead",
     lambda m, image, vertices: "%s of the %s rows of normals are zero or not finite: those vertices take the "
                                "volume's gradient instead" % (m.group(1), m.group(2))),
    (r"set Component to one of 0\.\.(-?\d+) \(got (-?\d+)\)",
     lambda m, image, vertices: "pass component, one of 0..%s (got %s)"
     % (m.group(1), "None" if m.group(2) == "-1" else m.group(2))),
]]


def numpy_terms(text, image=None, vertices=False):
    """A filter's message in the numpy functions' terms: voxels, shapes, axes and spacings
    in array order [z, y, x] (the filters speak VTK's (x, y, z)), and numpy's remedies
    where they name ParaView's filters. `image`: the volume, whose extent turns a voxel
    into an index of the results; `vertices`: the filter's points are the vertices given."""
    for pattern, replacement in _TRANSLATIONS:
        text = pattern.sub(lambda match: replacement(match, image, vertices), text)
    return text


class _Bar:
    """A progress bar: tqdm's when it is installed, else a line on stderr."""

    def __init__(self, label):
        self.label = label
        self.shown = -1
        try:
            from tqdm.auto import tqdm
        except ImportError:
            self.tqdm = None
        else:
            self.tqdm = tqdm(total=100, desc=label,
                             bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}]")

    def __call__(self, fraction):
        percent = int(max(0.0, min(1.0, fraction)) * 100)
        if percent <= self.shown:
            return
        if self.tqdm is not None:
            self.tqdm.update(percent - max(self.shown, 0))
        else:
            filled = percent // 5
            sys.stderr.write("\r%s [%s%s] %3d%%" % (self.label, "#" * filled, " " * (20 - filled), percent))
            sys.stderr.flush()
        self.shown = percent

    def close(self):
        if self.tqdm is not None:
            self.tqdm.close()
        elif self.shown >= 0:
            sys.stderr.write("\n")
            sys.stderr.flush()


def _progress_callback(progress, label):
    if progress is None or progress is False:
        return None
    if progress is True:
        return _Bar(label)
    if callable(progress):
        return progress
    raise TypeError("progress must be True, False or a callable taking the fraction done, got %r" % (progress,))


def run(algorithm, progress=False, cuda_asked=False, label=None, image=None, vertices=False):
    """Updates `algorithm`: its errors raise, its warnings are warned, its progress is
    shown. Warnings point at the caller's caller (the user's call of a public function).

    An error the filter reports about its arguments or data raises ValueError with its
    sentence; a computation that failed (memory, a device, another process) RuntimeError.
    Both, and the warnings, speak numpy's terms (numpy_terms, with `image` and `vertices`).
    """
    name = algorithm.GetClassName()
    if cuda_asked:
        warnings.warn("%s has no CUDA backend: it runs on the CPU" % name, VolumetricAOWarning, stacklevel=3)
    errors, notes = [], []

    @calldata_type(VTK_STRING)
    def on_error(caller, event, message):
        errors.append(filter_sentence(message))

    @calldata_type(VTK_STRING)
    def on_warning(caller, event, message):
        notes.append(filter_sentence(message))

    bar = _progress_callback(progress, label or name)

    def on_progress(caller, event):
        bar(caller.GetProgress())

    observed = [algorithm, algorithm.GetExecutive()]
    tags = []
    for subject in observed:
        tags.append((subject, subject.AddObserver(vtkCommand.ErrorEvent, on_error)))
        tags.append((subject, subject.AddObserver(vtkCommand.WarningEvent, on_warning)))
    if bar is not None:
        tags.append((algorithm, algorithm.AddObserver(vtkCommand.ProgressEvent, on_progress)))
    try:
        algorithm.Update()
    finally:
        for subject, tag in tags:
            subject.RemoveObserver(tag)
        if isinstance(bar, _Bar):
            bar.close()
    for note in notes:
        warnings.warn(numpy_terms(note, image, vertices), VolumetricAOWarning, stacklevel=3)
    if errors:
        text = "\n".join(dict.fromkeys(e for e in errors if e)) or "%s failed" % name
        # Which kind is read from the filter's own words.
        raise (RuntimeError if _FAILURE.search(text) else ValueError)(numpy_terms(text, image, vertices))
    return algorithm.GetOutputDataObject(0)


def point_arrays(output, names, shape, name_of=None):
    """The named point arrays of `output` as numpy arrays of `shape` (plus components):
    views of the filter's own arrays, not copies, so the output is never written twice;
    each view holds its VTK array, so the memory lives as long as the result."""
    results = []
    for name in names:
        array = output.GetPointData().GetArray(name) if output is not None else None
        if array is None and 0 in tuple(shape):
            results.append(np.zeros(shape, np.float32))  # nothing to compute: no array
            continue
        if array is None:
            raise RuntimeError("%s gave no %s array" % (name_of or "the filter", name))
        values = vtk_to_numpy(array)
        components = array.GetNumberOfComponents()
        results.append(values.reshape(tuple(shape) + ((components,) if components > 1 else ())))
    return results


def run_info(output, reported):
    """What ran: from the output's field data where the filter reports it (`reported`;
    other filters pass on their input's, which says what ran upstream), else the CPU."""
    fields = output.GetFieldData() if output is not None and reported else None

    def string(name):
        array = fields.GetAbstractArray(name) if fields is not None else None
        return array.GetValue(0) if array is not None and array.GetNumberOfValues() else None

    threads = fields.GetArray("AmbientOcclusionThreads") if fields is not None else None
    return RunInfo(backend=string("AmbientOcclusionBackend") or "CPU",
                   device=string("AmbientOcclusionDevice") or "CPU",
                   threads=int(threads.GetTuple1(0)) if threads is not None and threads.GetNumberOfTuples() else None)


def finish(result, output, return_info, reported=False):
    return (result, run_info(output, reported)) if return_info else result
