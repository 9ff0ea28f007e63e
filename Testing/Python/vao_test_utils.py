"""Shared helpers of the pvpython / pvbatch tests (no VolumetricAO code here)."""
import os
import sys

import numpy as np

# In the order the Method menu lists them (the default first).
METHODS = ["Histogram CDF", "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box", "Exact Sphere"]

# SaveData's options for every XML file the tests write: inline binary (base64) data.
# Appended data, raw or base64, is what ParaView writes by default, and VTK 9.2's XML reader
# cannot parse it with the libexpat1 of a current Debian 12 (2.5.0-1+deb12u2 and later
# defer reparsing, and the reader's early stop at <AppendedData> then fails as "not
# well-formed (invalid token)").
XML_OPTIONS = dict(DataMode="Binary")


# The collecting idiom of the Python package's tests: every check prints ok or FAILED and
# the run goes on; the script ends with finish(), which exits non-zero on a failure.
failures = []


def record(condition, what):
    print(("ok: " if condition else "FAILED: ") + what, flush=True)
    if not condition:
        failures.append(what)


def same(a, b):
    """Equal bit for bit: the same dtype, shape and values."""
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)


def finish(passed_line):
    print("FAILED" if failures else passed_line)
    sys.exit(1 if failures else 0)


def fail(message):
    print("FAILED: " + message)
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)
    print("ok: " + message)


def array_of(data_object, name):
    """Point array `name` of a vtkImageData as a numpy array (float64)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    array = data_object.GetPointData().GetArray(name)
    if array is None:
        fail("no point array %r" % name)
    return vtk_to_numpy(array).astype("float64")


def read_image(path):
    """Reads .vti / .pvti / .mha with VTK's own readers, serially."""
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPImageDataReader
    from vtkmodules.vtkIOImage import vtkMetaImageReader
    extension = os.path.splitext(path)[1].lower()
    reader = {".vti": vtkXMLImageDataReader, ".pvti": vtkXMLPImageDataReader,
              ".mha": vtkMetaImageReader}[extension]()
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
