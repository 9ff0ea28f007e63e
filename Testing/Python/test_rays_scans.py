"""Rays against Exact Rays (its definition, docs/methods.md sections 11 and 12) on 32^3
crops of the four shipped scans, three opacity functions each (a ramp onto dense material,
a faint ramp onto soft tissue, a narrow band), R = 4 and 8 voxels: on the voxels the
function shows, the RMSE at most 0.05 and the Pearson correlation at least 0.98 in every
case but the CT head's band, where the crop's faces hold most of the shown voxels (at least
0.93 there). Then what holds whatever the data: an opacity of 0 everywhere is open, the
result does not depend on the threads, and a crop's piece grown by the filter's reach gives
the whole crop's numbers.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_rays_scans.py SITE_PACKAGES_DIR DATA_DIR"""
import os
import sys

sys.path.insert(0, sys.argv[1])
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

from vao_test_utils import check, finish, read_image  # noqa: E402

data = sys.argv[2]
SIZE = 32
SCANS = [
    ("ct_head_phantom/ct_head_phantom_128x128x136_int16.mha", (16, 80, 40),
     {"bone": [(300, 0.0), (800, 0.9)], "soft": [(-600, 0.0), (0, 0.2)],
      "band": [(-350, 0.0), (-250, 0.6), (-150, 0.0)]}),
    ("lidc2_ct_chest/LIDC2_256x256x133_uint8.mha", (40, 136, 112),
     {"bone": [(140, 0.0), (220, 0.9)], "soft": [(30, 0.0), (110, 0.3)],
      "band": [(70, 0.0), (90, 0.7), (110, 0.0)]}),
    ("head_mr_small/HeadMRVolume.mhd", (5, 16, 8),
     {"bright": [(80, 0.0), (160, 0.9)], "soft": [(15, 0.0), (80, 0.25)],
      "band": [(30, 0.0), (45, 0.6), (60, 0.0)]}),
    ("headsq/headsq_64x64x93_int16.vti", (24, 16, 16),
     {"bone": [(1200, 0.0), (2200, 0.9)], "soft": [(400, 0.0), (900, 0.3)],
      "band": [(500, 0.0), (700, 0.6), (900, 0.0)]}),
]
for name, (z0, y0, x0), functions in SCANS:
    image = read_image(os.path.join(data, name))
    nx, ny, nz = image.GetDimensions()
    crop = np.ascontiguousarray(vtk_to_numpy(image.GetPointData().GetScalars())
                                .reshape(nz, ny, nx)[z0:z0 + SIZE, y0:y0 + SIZE, x0:x0 + SIZE])
    sampling = image.GetSpacing()[::-1]
    for function, points in functions.items():
        px, py = zip(*points)
        shown = np.interp(crop.astype(np.float64), px, py) > 0.01
        for radius in (4, 8):
            exact = volumetricao.ambient_occlusion(crop, radius=radius, method="exact rays", opacity=points,
                                                   sampling=sampling)
            fast = volumetricao.ambient_occlusion(crop, radius=radius, method="rays", opacity=points,
                                                  sampling=sampling)
            a, b = fast[shown].astype(np.float64), exact[shown].astype(np.float64)
            pearson = np.corrcoef(a, b)[0, 1]
            rmse = np.sqrt(np.mean((a - b) ** 2))
            least = 0.93 if (name.startswith("ct_head") and function == "band") else 0.98
            check(shown.sum() > 100 and rmse <= 0.05 and pearson >= least,
                  "%s %s R=%d: Rays against Exact Rays on %d shown voxels: Pearson %.3f (at least %.2f), "
                  "RMSE %.3f" % (os.path.basename(name), function, radius, shown.sum(), pearson, least, rmse))

# Open where nothing is opaque; the same bits on 1 and 3 threads.
ct = read_image(os.path.join(data, SCANS[0][0]))
nx, ny, nz = ct.GetDimensions()
head = np.ascontiguousarray(vtk_to_numpy(ct.GetPointData().GetScalars()).reshape(nz, ny, nx)[40:72, 40:80, 30:70])
empty = volumetricao.ambient_occlusion(head, radius=5, method="rays", opacity=[(0, 0.0), (1, 0.0)])
check(np.abs(empty - 1.0).max() <= 1e-6, "an opacity of 0 everywhere is open (max |AO - 1| %.2g)"
      % np.abs(empty - 1.0).max())
bone = [(300, 0.0), (800, 0.9)]
one = volumetricao.ambient_occlusion(head, radius=5, method="rays", opacity=bone, threads=1, sampling=(2, 1.95, 1.95))
three = volumetricao.ambient_occlusion(head, radius=5, method="rays", opacity=bone, threads=3,
                                       sampling=(2, 1.95, 1.95))
check(np.array_equal(one, three) and one.min() < 0.5, "the same bits on 1 and 3 threads (AO %.3f..%.3f)"
      % (one.min(), one.max()))
finish("Rays is within the bar of Exact Rays on the scans")
