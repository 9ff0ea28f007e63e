"""Shared helpers of the pvpython / pvbatch tests (no VolumetricAO code here)."""
import os
import sys

METHODS = ["CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box", "Exact Sphere"]


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
