"""Salt and pepper of the AO in homogeneous regions of the shipped CT head: the mean
difference between x-neighbours in the air (below -900 HU, 6 voxels from anything else)
and in soft tissue, and the time, for the voxel-value query and the smoothed one
(docs/filters/volumetric-ambient-occlusion.md, "Speckle").

Usage: python3 Benchmarks/speckle.py BUILD_SITE_PACKAGES [DATA_DIR]"""
import os
import sys
import time

import numpy as np
from scipy import ndimage

sys.path.insert(0, sys.argv[1])
import volumetricao  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOImage import vtkMetaImageReader  # noqa: E402

data = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "Data")
reader = vtkMetaImageReader()
reader.SetFileName(os.path.join(data, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha"))
reader.Update()
image = reader.GetOutput()
nx, ny, nz = image.GetDimensions()
volume = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx)
air = ndimage.binary_erosion(volume < -900, iterations=6)
tissue = ndimage.binary_erosion((volume > -200) & (volume < 200), iterations=2)


def speckle(ao, mask):
    both = mask[:, :, 1:] & mask[:, :, :-1]
    return float(np.abs(np.diff(ao, axis=2))[both].mean())


print("%-26s %10s %10s %10s" % ("query", "air", "tissue", "seconds"))
for label, extra in (("voxel value", {}), ("smoothed, sigma 1", {"query_smoothing": 1.0}),
                     ("smoothed, sigma 2", {"query_smoothing": 2.0})):
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        ao = volumetricao.ambient_occlusion(volume, radius=10, sampling=image.GetSpacing()[::-1], **extra)
        best = min(best, time.perf_counter() - start)
    print("%-26s %10.3f %10.3f %10.3f" % (label, speckle(ao, air), speckle(ao, tissue), best))
