"""Histogram CDF's error against Exact Box for several bin counts and two threshold placements.

Prints, as Markdown rows, the RMSE of Histogram CDF against Exact Box on the shipped CT
head phantom (128x128x136, int16) for NumberOfBins 32, 48, 64, 96 and 128 at R = 3, 5 and
10 voxels, with the filter's own threshold placement and with plain global quantiles
(thresholds at the K evenly spaced quantiles of the whole volume's values, given to the
filter through SetHistogramThresholds). docs/methods.md (section 8) and docs/accuracy.md
quote these rows. Not a ctest: it prints, and checks nothing.

usage: python3 Testing/Python/histogram_cdf_bins.py PACKAGE_DIR [SCAN]
  PACKAGE_DIR: build/lib/python3.11/site-packages (or the install's)
  SCAN: default Data/ct_head_phantom/ct_head_phantom_128x128x136_int16.mha
"""
import os
import sys

sys.path.insert(0, sys.argv[1])
import numpy as np  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOImage import vtkMetaImageReader  # noqa: E402
from volumetricao.VolumetricAOFilters import vtkVolumetricAmbientOcclusion as V  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
scan = sys.argv[2] if len(sys.argv) > 2 else os.path.join(
    ROOT, "Data", "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha")

reader = vtkMetaImageReader()
reader.SetFileName(scan)
reader.Update()
image = reader.GetOutput()
values = vtk_to_numpy(image.GetPointData().GetScalars())
visible = values > values.min() + 0.1 * (float(values.max()) - float(values.min()))


def openness(radius, method, bins=64, thresholds=None):
    f = V()
    f.SetInputData(image)
    f.SetRadius(radius)
    f.SetMethod(method)
    f.SetNumberOfBins(bins)
    if thresholds is not None:
        f.SetHistogramThresholds(numpy_to_vtk(np.asarray(thresholds, dtype=np.float64), deep=1))
    f.Update()
    return vtk_to_numpy(f.GetOutput().GetPointData().GetArray("AmbientOcclusion")).astype(np.float64)


def rmse(a, b, mask=None):
    d = (a - b) if mask is None else (a - b)[mask]
    return float(np.sqrt(np.mean(d * d)))


print("| placement | bins | R | RMSE all voxels | RMSE visible voxels |")
print("|---|---|---|---|---|")
for radius in (3, 5, 10):
    exact = openness(radius, V.EXACT_BOX)
    for bins in (32, 48, 64, 96, 128):
        ours = openness(radius, V.HISTOGRAM_CDF, bins)
        print("| filter's own | %d | %d | %.3f | %.3f |"
              % (bins, radius, rmse(ours, exact), rmse(ours, exact, visible)))
    for bins in (32, 64):
        quantiles = np.unique(np.quantile(values, np.linspace(0.0, 1.0, bins)))
        plain = openness(radius, V.HISTOGRAM_CDF, bins, quantiles)
        print("| global quantiles | %d | %d | %.3f | %.3f |"
              % (bins, radius, rmse(plain, exact), rmse(plain, exact, visible)))
    sys.stdout.flush()
