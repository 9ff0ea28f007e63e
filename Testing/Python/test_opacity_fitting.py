"""pvpython: an opacity transfer function ParaView made but never fitted to data (a step at
0..1 in the data's units) is fitted to the filter's Scalars before the filter reads it, so
that the first result equals the result once the array is coloured; a function whose
points were set is left alone; the numpy functions refuse an untouched one with advice.

Usage: pvpython test_opacity_fitting.py PLUGIN DATA_DIR PYTHON_PACKAGE_DIR"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish  # noqa: E402

plugin, data_dir, package_dir = sys.argv[1:4]
sys.path.insert(0, package_dir)
from paraview.simple import *  # noqa: E402,F401,F403
from paraview import servermanager  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
import numpy as np  # noqa: E402

LoadPlugin(plugin, ns=globals())
path = os.path.join(data_dir, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha")


def values(proxy, array):
    proxy.UpdatePipeline()
    data = servermanager.Fetch(proxy)
    return vtk_to_numpy(data.GetPointData().GetArray(array)).copy()


FRESH = [0.0, 0.0, 0.5, 0.0, 1.0, 1.0, 0.5, 0.0]
ct = OpenDataFile(path)
function = GetOpacityTransferFunction("MetaImage")
check(list(function.Points) == FRESH and function.ScalarRangeInitialized == 0, "a new opacity function is (0,0)-(1,1)")
ao = VolumetricAmbientOcclusion(Input=ct, Radius=4, Method="Transfer Function", OpacityFunction=function)
first = values(ao, "AmbientOcclusion")
lo, hi = ct.PointData["MetaImage"].GetRange()
check(list(function.Points) == [lo, 0.0, 0.5, 0.0, hi, 1.0, 0.5, 0.0],
      "Transfer Function fits it to the Scalars' range %s (got %s)" % ((lo, hi), list(function.Points)))
display = Show(ct)
ColorBy(display, ("POINTS", "MetaImage"))
display.RescaleTransferFunctionToDataRange(False, True)
colored = values(ao, "AmbientOcclusion")
check(np.array_equal(first, colored), "the first result equals the result once the array is coloured")
check(first.max() - first.min() > 0.1, "the result is not a step at 0..1 HU (range %g..%g)" % (first.min(), first.max()))

# Points the user set stay as they are, even with the range never initialised.
ct2 = OpenDataFile(path)
mine = GetOpacityTransferFunction("Mine")
mine.Points = [-500.0, 0.0, 0.5, 0.0, 1500.0, 1.0, 0.5, 0.0]
ao2 = VolumetricAmbientOcclusion(Input=ct2, Radius=4, Method="Transfer Function", OpacityFunction=mine)
ao2.UpdatePipeline()
check(list(mine.Points) == [-500.0, 0.0, 0.5, 0.0, 1500.0, 1.0, 0.5, 0.0], "a function with set points is kept")

# Other methods leave an attached function alone until Transfer Function is chosen.
other = GetOpacityTransferFunction("Other")
ao3 = VolumetricAmbientOcclusion(Input=ct2, Radius=4, OpacityFunction=other)
check(list(other.Points) == FRESH, "Histogram CDF does not touch the function it ignores")
ao3.Method = "Transfer Function"
check(list(other.Points)[0] == lo and list(other.Points)[4] == hi, "choosing Transfer Function fits it")

# Ambient Occlusion Shading's opacity function, likewise.
shading_function = GetOpacityTransferFunction("ShadingOpacity")
shading = AmbientOcclusionShading(Input=ao, Scalars=["POINTS", "MetaImage"], OpacityTransferFunction=shading_function)
check(list(shading_function.Points)[0] == lo and list(shading_function.Points)[4] == hi,
      "the Shading's untouched opacity function is fitted too")

# numpy: refused with advice, accepted once fitted.
import volumetricao  # noqa: E402
volume = np.random.default_rng(3).normal(size=(16, 17, 18)).astype(np.float32)
untouched = GetOpacityTransferFunction("Numpy")
try:
    volumetricao.ambient_occlusion(volume, radius=2, method="transfer function", opacity=untouched)
    check(False, "numpy refuses an untouched opacity function")
except ValueError as error:
    check("never fitted" in str(error) and "RescaleTransferFunction" in str(error),
          "numpy refuses an untouched opacity function, saying how to fit it: %s" % error)
untouched.RescaleTransferFunction(float(volume.min()), float(volume.max()))
fitted = volumetricao.ambient_occlusion(volume, radius=2, method="transfer function", opacity=untouched)
points = np.array([[volume.min(), 0.0], [volume.max(), 1.0]])
expected = volumetricao.ambient_occlusion(volume, radius=2, method="transfer function", opacity=points)
check(np.array_equal(fitted, expected), "once fitted, numpy takes it (equal to the same points given)")
finish("untouched opacity functions are fitted or refused")
