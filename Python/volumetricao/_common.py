"""What the numpy functions share: reading their arguments the scipy way, building the
vtkImageData, running a filter with Python's errors, warnings and progress, and the
report of what ran."""
import collections
import numbers
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
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral):
        raise TypeError("threads must be an integer (0: the cores this process may use), got %r" % (threads,))
    return int(threads)


def number(value, name):
    """A float, or TypeError naming the argument."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise TypeError("%s must be a number, got %r" % (name, value)) from None


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
        if isinstance(function, vtkPiecewiseFunction):
            return function
        raise TypeError("%s: %r is not an opacity (piecewise) transfer function" % (name, opacity))
    try:
        points = np.asarray(opacity, dtype=float)
    except (TypeError, ValueError):
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


def three(value, name):
    """Three floats from a scalar or a sequence of three."""
    try:
        values = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise TypeError("%s: numbers expected, got %r" % (name, value)) from None
    if values.size == 1:
        values = np.repeat(values, 3)
    if values.size != 3:
        raise ValueError("%s: one value, or one per array axis (3), got %d" % (name, values.size))
    return tuple(float(v) for v in values)


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
        if isinstance(component, bool) or not isinstance(component, numbers.Integral):
            raise TypeError("component must be an integer, got %r" % (component,))
        algorithm.SetComponent(int(component))


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


def run(algorithm, progress=False, cuda_asked=False, label=None):
    """Updates `algorithm`: its errors raise, its warnings are warned, its progress is
    shown. Warnings point at the caller's caller (the user's call of a public function).

    An error the filter reports about its arguments or data raises ValueError with its
    sentence; a computation that failed (memory, a device, another process) RuntimeError.
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
        warnings.warn(note, VolumetricAOWarning, stacklevel=3)
    if errors:
        text = "\n".join(dict.fromkeys(e for e in errors if e)) or "%s failed" % name
        raise (RuntimeError if _FAILURE.search(text) else ValueError)(text)
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
