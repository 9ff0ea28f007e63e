"""Every Volumetric AO method against Exact Rays (the ambient occlusion a ray tracer shows,
docs/methods.md section 11) on crops of the shipped scans, three opacity functions each,
R = 4 and 8 voxels: Pearson correlation and plain RMSE on the voxels the function shows
(alpha > 0.01), on all voxels and on the surface voxels (shown, with a 6-neighbour not
shown). Each crop is its own volume for every method. Prints a markdown table
(docs/accuracy.md, "Against the rays").

Usage: python3 Benchmarks/rays_accuracy.py BUILD_SITE_PACKAGES [DATA_DIR] [--quick]
(--quick: R = 4 only and 24^3 crops, about a minute.)"""
import os
import sys
import time

import numpy as np

sys.path.insert(0, sys.argv[1])
import volumetricao  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOImage import vtkMetaImageReader  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLImageDataReader  # noqa: E402

args = [a for a in sys.argv[2:] if not a.startswith("--")]
quick = "--quick" in sys.argv
data = args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Data")

# scan file, crop start [z, y, x], functions: name -> points (value, opacity), linear between
SCANS = [
    ("ct_head_phantom/ct_head_phantom_128x128x136_int16.mha", (8, 72, 32),
     {"bone": [(300, 0.0), (800, 0.9)], "soft": [(-600, 0.0), (0, 0.2)],
      "band": [(-350, 0.0), (-250, 0.6), (-150, 0.0)]}),
    ("lidc2_ct_chest/LIDC2_256x256x133_uint8.mha", (32, 128, 104),
     {"bone": [(140, 0.0), (220, 0.9)], "soft": [(30, 0.0), (110, 0.3)],
      "band": [(70, 0.0), (90, 0.7), (110, 0.0)]}),
    ("head_mr_small/HeadMRVolume.mhd", (0, 8, 0),
     {"bright": [(80, 0.0), (160, 0.9)], "soft": [(15, 0.0), (80, 0.25)],
      "band": [(30, 0.0), (45, 0.6), (60, 0.0)]}),
    ("headsq/headsq_64x64x93_int16.vti", (16, 8, 8),
     {"bone": [(1200, 0.0), (2200, 0.9)], "soft": [(400, 0.0), (900, 0.3)],
      "band": [(500, 0.0), (700, 0.6), (900, 0.0)]}),
]
SIZE = 24 if quick else 48
RADII = (4,) if quick else (4, 8)


def read(path):
    reader = vtkXMLImageDataReader() if path.endswith(".vti") else vtkMetaImageReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    nx, ny, nz = image.GetDimensions()
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx), image.GetSpacing()


def scores(a, b, mask):
    if mask.sum() < 10:
        return float("nan"), float("nan")
    x, y = a[mask].astype(np.float64), b[mask].astype(np.float64)
    pearson = np.corrcoef(x, y)[0, 1] if x.std() > 0 and y.std() > 0 else float("nan")
    return pearson, float(np.sqrt(np.mean((x - y) ** 2)))


def methods(crop, sampling, points, radius):
    common = dict(radius=radius)
    yield "Histogram CDF", volumetricao.ambient_occlusion(crop, **common)
    yield "Gaussian CDF", volumetricao.ambient_occlusion(crop, method="gaussian cdf", **common)
    yield "Transfer Function", volumetricao.ambient_occlusion(crop, method="transfer function", opacity=points,
                                                              **common)
    yield "Rays", volumetricao.ambient_occlusion(crop, method="rays", opacity=points, sampling=sampling, **common)


rows = []
start = time.time()
for name, (z0, y0, x0), functions in SCANS:
    values, spacing = read(os.path.join(data, name))
    crop = np.ascontiguousarray(values[z0:z0 + SIZE, y0:y0 + SIZE, x0:x0 + SIZE])
    sampling = spacing[::-1]
    for function, points in functions.items():
        px, py = zip(*points)
        shown = np.interp(crop.astype(np.float64), px, py) > 0.01
        hidden = ~shown
        near_hidden = np.zeros_like(shown)
        for axis in range(3):
            for step in (1, -1):
                rolled = np.roll(hidden, step, axis=axis)
                edge = [slice(None)] * 3
                edge[axis] = 0 if step == 1 else -1
                rolled[tuple(edge)] = False
                near_hidden |= rolled
        surface = shown & near_hidden
        for radius in RADII:
            rays = volumetricao.ambient_occlusion(crop, radius=radius, method="exact rays", opacity=points,
                                                  sampling=sampling)
            for method, ao in methods(crop, sampling, points, radius):
                rows.append((os.path.basename(os.path.dirname(name)), function, radius, method,
                             scores(ao, rays, shown), scores(ao, rays, np.ones_like(shown)),
                             scores(ao, rays, surface), float(np.median(rays[shown])) if shown.any() else float("nan")))

print("| scan | function | R | method | Pearson / RMSE, shown | all voxels | surface | median Exact Rays (shown) |")
print("|---|---|---|---|---|---|---|---|")
for scan, function, radius, method, shown, every, surface, median in rows:
    print("| %s | %s | %d | %s | %.2f / %.3f | %.2f / %.3f | %.2f / %.3f | %.2f |"
          % (scan, function, radius, method, shown[0], shown[1], every[0], every[1], surface[0], surface[1], median))
print()
print("Range over every scan, function and radius (shown voxels):")
for method in dict.fromkeys(r[3] for r in rows):
    chosen = [r for r in rows if r[3] == method]
    pearson = [r[4][0] for r in chosen]
    rmse = [r[4][1] for r in chosen]
    print("- %s: Pearson %.2f to %.2f, RMSE %.3f to %.3f" % (method, np.nanmin(pearson), np.nanmax(pearson),
                                                              np.nanmin(rmse), np.nanmax(rmse)))
print("(%.0f s, %d^3 crops)" % (time.time() - start, SIZE))
