"""Shared helpers of the Python test scripts (no VolumetricAO code here). Standard library
only at import, so that test_docs.py runs without numpy or VTK."""
import os
import sys

# In the order the Method menu lists them (the default first).
METHODS = ["Histogram CDF", "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box", "Exact Sphere"]

# SaveData's options for every XML file the tests write: inline binary (base64) data.
# Appended data, raw or base64, is what ParaView writes by default, and VTK 9.2's XML reader
# cannot parse it with the libexpat1 of a current Debian 12 (2.5.0-1+deb12u2 and later
# defer reparsing, and the reader's early stop at <AppendedData> then fails as "not
# well-formed (invalid token)").
XML_OPTIONS = dict(DataMode="Binary")


# The one check idiom of the test scripts: check() prints "ok: what" or "FAILED: what" and
# records a failure, and the run goes on; finish() ends it, with exit status 1 after a
# failure. A check whose failure leaves nothing for the rest to test (a missing plugin, an
# unreadable file) passes stop=True, and the run ends there with status 1 (fail() is
# check(False, message, stop=True)). ctest reads "FAILED" in the output as well.
failures = []
_passed = 0


def check(condition, what, stop=False):
    """Prints and records one check; returns whether it passed."""
    global _passed
    print(("ok: " if condition else "FAILED: ") + what, flush=True)
    if condition:
        _passed += 1
        return True
    failures.append(what)
    if stop:
        sys.exit(1)
    return False


def fail(message):
    check(False, message, stop=True)


def summary():
    """The count of the checks so far, as "N passed, M failed"."""
    return "%d passed, %d failed" % (_passed, len(failures))


def finish(passed_line):
    print("FAILED" if failures else passed_line, flush=True)
    sys.exit(1 if failures else 0)


def same(a, b):
    """Equal bit for bit: the same dtype, shape and values."""
    import numpy as np
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)


def array_of(data_object, name):
    """Point array `name` of a vtkImageData as a numpy array (float64)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    array = data_object.GetPointData().GetArray(name)
    if array is None:
        fail("no point array %r" % name)
    return vtk_to_numpy(array).astype("float64")


def read_image(path):
    """Reads .vti / .pvti / .mha / .mhd with VTK's own readers, serially."""
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPImageDataReader
    from vtkmodules.vtkIOImage import vtkMetaImageReader
    extension = os.path.splitext(path)[1].lower()
    reader = {".vti": vtkXMLImageDataReader, ".pvti": vtkXMLPImageDataReader,
              ".mha": vtkMetaImageReader, ".mhd": vtkMetaImageReader}[extension]()
    reader.SetFileName(path)
    reader.Update()
    output = reader.GetOutput()
    if output.GetNumberOfPoints() == 0:
        fail("could not read back " + path)
    return output


def extent_logger(upstream, prefix):
    """(pvpython / pvbatch) A pass-through ProgrammableFilter that writes the extent it
    received to <prefix>.<rank>: what the filters downstream asked of `upstream`."""
    from paraview.simple import ProgrammableFilter
    logger = ProgrammableFilter(Input=upstream)
    logger.Script = """
from vtkmodules.vtkParallelCore import vtkMultiProcessController
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId() if controller else 0
data = self.GetInputDataObject(0, 0)
self.GetOutputDataObject(0).ShallowCopy(data)
with open(PREFIX + ".%d" % rank, "w") as log:
    log.write(" ".join(str(e) for e in data.GetExtent()))
""".replace("PREFIX", repr(prefix))
    return logger


def logged_extent(prefix, rank):
    """The extent extent_logger wrote for `rank`, as a tuple."""
    with open("%s.%d" % (prefix, rank)) as log:
        return tuple(int(v) for v in log.read().split())


def box_mean(values, radii):
    """The mean of `values` ([z, y, x]) over the box of half-widths `radii` (z, y, x) around
    each voxel, clipped to the volume: float64 cumulative sums, one axis at a time."""
    import numpy as np
    out = values.astype(np.float64)
    for axis, r in enumerate(radii):
        n = out.shape[axis]
        zero = np.zeros_like(np.take(out, [0], axis=axis))
        sums = np.concatenate([zero, np.cumsum(out, axis=axis)], axis=axis)
        hi, lo = np.minimum(np.arange(n) + r + 1, n), np.maximum(np.arange(n) - r, 0)
        shape = [1, 1, 1]
        shape[axis] = n
        out = (np.take(sums, hi, axis=axis) - np.take(sums, lo, axis=axis)) / (hi - lo).reshape(shape)
    return out


def opacity_openness(values, function, radii):
    """The Transfer Function method's reference: 1 - box_mean of the opacity that
    vtkPiecewiseFunction.GetValue itself gives each voxel (once per distinct value)."""
    import numpy as np
    distinct, inverse = np.unique(values, return_inverse=True)
    alpha = np.array([function.GetValue(float(v)) for v in distinct])[inverse].reshape(values.shape)
    return 1.0 - box_mean(alpha, radii)


def errors_of(algorithm):
    """The list that collects the error messages `algorithm` will emit."""
    from vtkmodules.util.misc import calldata_type
    from vtkmodules.vtkCommonCore import VTK_STRING, vtkCommand
    errors = []

    @calldata_type(VTK_STRING)
    def collect(caller, event, message):
        errors.append(message)

    algorithm.AddObserver(vtkCommand.ErrorEvent, collect)
    return errors


def serial_surface_values(make, surface, volume, name):
    """The array `name` that a new filter from `make` (Isosurface AO, Probe Outside Surface)
    gives at a copy of `surface`'s points in `volume`, in one process (no controller)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    points = surface.NewInstance()
    points.DeepCopy(surface)
    serial = make()
    if hasattr(serial, "SetController"):
        serial.SetController(None)
    serial.SetInputData(0, points)
    serial.SetInputData(1, volume)
    serial.Update()
    return vtk_to_numpy(serial.GetOutput().GetPointData().GetArray(name))
