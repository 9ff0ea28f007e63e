"""The cost of Rays and Exact Rays against the Gaussian CDF, in one process through the numpy
API, on whole volumes at R = 10 voxels (the bar of Rays: at most 4x the Gaussian CDF): the
shipped CT head and LIDC2 chest, a bone opacity; Gaussian CDF and Rays alternate in each of
3 rounds (this machine's speed drifts), the median ratio is printed. Exact Rays is timed on 4
middle slices and extrapolated by voxel count.

Usage: python3 Benchmarks/rays_cost.py BUILD_SITE_PACKAGES [DATA_DIR]"""
import os
import sys
import time

import numpy as np

sys.path.insert(0, sys.argv[1])
import volumetricao  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOImage import vtkMetaImageReader  # noqa: E402

data = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data")
SCANS = [("ct_head_phantom/ct_head_phantom_128x128x136_int16.mha", [(300, 0.0), (800, 0.9)]),
         ("lidc2_ct_chest/LIDC2_256x256x133_uint8.mha", [(140, 0.0), (220, 0.9)])]


def seconds(call):
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


print("%-28s %10s %10s %8s %14s %8s" % ("volume", "Gaussian", "Rays", "ratio", "Exact Rays~", "ratio"))
for name, points in SCANS:
    reader = vtkMetaImageReader()
    reader.SetFileName(os.path.join(data, name))
    reader.Update()
    image = reader.GetOutput()
    nx, ny, nz = image.GetDimensions()
    volume = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx)
    sampling = image.GetSpacing()[::-1]
    gaussian, rays, ratios = [], [], []
    for _ in range(3):
        g = seconds(lambda: volumetricao.ambient_occlusion(volume, radius=10, method="gaussian cdf"))
        r = seconds(lambda: volumetricao.ambient_occlusion(volume, radius=10, method="rays", opacity=points,
                                                           sampling=sampling))
        gaussian.append(g)
        rays.append(r)
        ratios.append(r / g)
    middle = nz // 2
    slab = np.ascontiguousarray(volume[middle:middle + 4])
    exact = seconds(lambda: volumetricao.ambient_occlusion(slab, radius=10, method="exact rays", opacity=points,
                                                           sampling=sampling)) * nz / 4
    print("%-28s %9.3fs %9.3fs %7.0fx %13.1fs %7.0fx" % (
        "%s %dx%dx%d" % (os.path.basename(os.path.dirname(name)), nx, ny, nz), np.median(gaussian),
        np.median(rays), np.median(ratios), exact, exact / np.median(gaussian)))
