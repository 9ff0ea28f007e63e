#!/usr/bin/python3
"""The peer of the sweeping benchmark: scipy.ndimage.distance_transform_edt on the
thresholded volume (an exact unsigned distance to the inside, the quantity users would
otherwise compute), and the signed distance (two EDTs and their difference). Prints
`edt seconds` and `signed seconds`.

Usage: scipy_edt_peer.py VOLUME_NXxNYxNZ_float32.raw ISO"""
import re
import sys
import time

import numpy as np
from scipy import ndimage

path, iso = sys.argv[1], float(sys.argv[2])
nx, ny, nz = (int(v) for v in re.search(r"_(\d+)x(\d+)x(\d+)_float32\.raw$", path).groups())
volume = np.fromfile(path, dtype="<f4").reshape(nz, ny, nx)
start = time.perf_counter()
ndimage.distance_transform_edt(volume <= iso)  # distance of every outside voxel to the inside
print("edt %.4f" % (time.perf_counter() - start), flush=True)
# The signed distance, what the sweeping's SignedDistance gives (issue 14's peer), timed
# whole: the outside voxels' distance again, the inside voxels' distance to the outside,
# and their difference.
start = time.perf_counter()
outside = ndimage.distance_transform_edt(volume <= iso)
signed = outside - ndimage.distance_transform_edt(volume > iso)
print("signed %.4f" % (time.perf_counter() - start), flush=True)
