"""How often the numpy functions report progress on a long run with the default threads:
the calls and the largest step between two reports (and from 0 to the first), for each of
the five functions (ambient_occlusion with four methods) on a 320 x 400 x 400 volume.

Usage: python3 Benchmarks/progress_steps.py BUILD_SITE_PACKAGES [SHAPE_Z SHAPE_Y SHAPE_X]"""
import sys
import time

import numpy as np

sys.path.insert(0, sys.argv[1])
import volumetricao  # noqa: E402

shape = tuple(int(n) for n in sys.argv[2:5]) if len(sys.argv) >= 5 else (320, 400, 400)
volume = np.random.default_rng(1).normal(size=shape).astype(np.float32)
# A surface across the middle of the volume: 100 x 4000 vertices facing +z.
z, y, x = shape
grid = np.meshgrid([z / 2], np.linspace(2, y - 3, 100), np.linspace(2, x - 3, 4000), indexing="ij")
vertices = np.stack(grid, -1).reshape(-1, 3)
normals = np.tile([1.0, 0.0, 0.0], (len(vertices), 1))

runs = (
    ("ambient_occlusion (Histogram CDF)", lambda p: volumetricao.ambient_occlusion(volume, radius=6, progress=p)),
    ("ambient_occlusion (Gaussian CDF)",
     lambda p: volumetricao.ambient_occlusion(volume, radius=6, method="gaussian cdf", progress=p)),
    ("ambient_occlusion (smoothed query)",
     lambda p: volumetricao.ambient_occlusion(volume, radius=6, query_smoothing=1.5, progress=p)),
    ("ambient_occlusion (Transfer Function)",
     lambda p: volumetricao.ambient_occlusion(volume, radius=6, method="transfer function",
                                              opacity=[(-0.1, 0), (0.1, 1)], progress=p)),
    ("occlusion_sweeping", lambda p: volumetricao.occlusion_sweeping(volume, 0.0, progress=p)),
    ("variance_occlusion_map", lambda p: volumetricao.variance_occlusion_map(volume, progress=p)),
    ("isosurface_ambient_occlusion",
     lambda p: volumetricao.isosurface_ambient_occlusion(volume, vertices, normals, iso_value=0.0, progress=p)),
    ("shade", lambda p: volumetricao.shade(volume, np.ones_like(volume), progress=p)),
)
print("%-40s %6s %9s %8s" % ("function", "calls", "max step", "seconds"))
for name, call in runs:
    seen = []
    start = time.perf_counter()
    call(seen.append)
    seconds = time.perf_counter() - start
    rises = [0.0] + seen
    print("%-40s %6d %9.3f %8.2f" % (name, len(seen), max(b - a for a, b in zip(rises, rises[1:])), seconds))
