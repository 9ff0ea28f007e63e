"""Exact Rays on crops of the shipped scans against the tests' own ray caster, written here
from docs/methods.md section 11 with numpy: Fibonacci directions, world steps turned into
index coordinates through the inverse of the image's frame, trilinear values by hand, the
opacity by np.interp between the function's points (clamped), extinction and transmittance
in float64. Anisotropic CT and MR, R = 4 and 8 voxels, a voxel and a world radius, an
opacity unit distance, a rotated image (vtkImageData with a direction matrix). Every voxel
within 2e-5, and RMS within 1e-6.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_exact_rays_scans.py SITE_PACKAGES_DIR DATA_DIR"""
import os
import sys

sys.path.insert(0, sys.argv[1])
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402

from vao_test_utils import check, finish, read_image  # noqa: E402


def fibonacci(n):
    i = np.arange(n)
    z = 1 - (2 * i + 1) / n
    r = np.sqrt(1 - z * z)
    phi = (i + 0.5) * np.pi * (3 - np.sqrt(5))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def trilinear(values, q):
    """Values [z, y, x] at index coordinates q (..., 3) in (x, y, z); NaN outside."""
    dims = np.array(values.shape[::-1])
    inside = np.all((q >= 0) & (q <= dims - 1), axis=-1)
    lo = np.clip(np.floor(q).astype(np.int64), 0, np.maximum(dims - 2, 0))
    f = q - lo
    hi = np.minimum(lo + 1, dims - 1)
    lo = np.where(inside[..., None], lo, 0)
    hi = np.where(inside[..., None], hi, 0)
    total = 0.0
    for corner in range(8):
        pick = [(corner >> a) & 1 for a in range(3)]
        idx = [np.where(pick[a], hi[..., a], lo[..., a]) for a in range(3)]
        weight = np.ones(q.shape[:-1])
        for a in range(3):
            weight = weight * (f[..., a] if pick[a] else 1 - f[..., a])
        total = total + weight * values[idx[2], idx[1], idx[0]]
    return np.where(inside, total, np.nan)


def reference(values, spacing, direction, points, radius, unit, rays=128):
    """AO_ray of every voxel of `values` [z, y, x]; spacing (x, y, z); direction row-major."""
    h = np.asarray(spacing, float)
    d = np.asarray(direction, float).reshape(3, 3)
    m = int(np.ceil(radius / (h.min() / 2)))
    dt = radius / m
    xs, ys, zs = np.meshgrid(*(np.arange(n, dtype=float) for n in values.shape[::-1]), indexing="ij")
    voxels = np.stack([xs, ys, zs], axis=-1).reshape(-1, 3)  # index coordinates (x, y, z)
    t = (np.arange(m) + 0.5) * dt
    px, py = zip(*points)
    total = np.zeros(len(voxels))
    for w in fibonacci(rays):
        move = (d.T @ w) / h  # index coordinates per world unit
        q = voxels[:, None, :] + t[None, :, None] * move[None, None, :]
        v = trilinear(values.astype(np.float64), q)
        alpha = np.minimum(np.interp(np.nan_to_num(v), px, py), 1 - 1e-6)
        sigma = np.where(np.isnan(v), 0.0, -np.log1p(-alpha) / unit)
        total += np.exp(-dt * sigma.sum(axis=1))
    # Back to [z, y, x].
    return (total / rays).reshape(values.shape[::-1]).transpose(2, 1, 0)


def image_of(values, spacing, direction):
    image = vtkImageData()
    image.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    image.SetSpacing(*spacing)
    image.SetDirectionMatrix(*direction)
    scalars = numpy_to_vtk(np.ascontiguousarray(values).ravel(), deep=True)
    scalars.SetName("values")
    image.GetPointData().SetScalars(scalars)
    return image


def compare(label, got, expected):
    difference = np.abs(got.astype(np.float64) - expected)
    check(difference.max() <= 2e-5 and np.sqrt(np.mean(difference ** 2)) <= 1e-6,
          "%s: max |Exact Rays - reference| %.2g, RMS %.2g (AO %.3f..%.3f)"
          % (label, difference.max(), np.sqrt(np.mean(difference ** 2)), expected.min(), expected.max()))


data = sys.argv[2]
IDENTITY = (1, 0, 0, 0, 1, 0, 0, 0, 1)
scans = [
    # file, crop [z, y, x] start, size, points (value, opacity)
    ("ct_head_phantom/ct_head_phantom_128x128x136_int16.mha", (60, 40, 50), 14,
     [(-200, 0.0), (150, 0.15), (400, 0.8), (1200, 0.95)]),
    ("lidc2_ct_chest/LIDC2_256x256x133_uint8.mha", (60, 140, 110), 14, [(60, 0.0), (120, 0.5), (200, 0.9)]),
    ("headsq/headsq_64x64x93_int16.vti", (40, 20, 20), 14, [(500, 0.0), (1200, 0.4), (2500, 1.0)]),
    ("head_mr_small/HeadMRVolume.mhd", (14, 20, 16), 14, [(20, 0.0), (60, 0.3), (120, 0.9)]),
]
for name, (z0, y0, x0), size, points in scans:
    image = read_image(os.path.join(data, name))
    nx, ny, nz = image.GetDimensions()
    whole = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx)  # the scan's own type
    crop = np.ascontiguousarray(whole[z0:z0 + size, y0:y0 + size, x0:x0 + size])
    spacing = image.GetSpacing()
    sampling = spacing[::-1]
    smallest = min(spacing)
    short = os.path.basename(name)
    for voxels in (4, 8):
        got = volumetricao.ambient_occlusion(crop, radius=voxels, method="exact rays", opacity=points,
                                             sampling=sampling)
        compare("%s R=%d voxels" % (short, voxels), got,
                reference(crop, spacing, IDENTITY, points, voxels * smallest, smallest))
    # A world radius between voxels, another unit distance, fewer rays.
    got = volumetricao.ambient_occlusion(crop, radius=2.7 * smallest, world_radius=True, method="exact rays",
                                         opacity=points, sampling=sampling, opacity_unit_distance=3.0,
                                         ray_count=37)
    compare("%s world radius %.2f, unit distance 3, 37 rays" % (short, 2.7 * smallest), got,
            reference(crop, spacing, IDENTITY, points, 2.7 * smallest, 3.0, rays=37))

# A rotated image: its direction matrix turns the rays' world directions into other index
# directions (a 90-degree turn about z, then a tilt about x).
c, s = np.cos(0.4), np.sin(0.4)
turn = np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1]], float)
tilt = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
direction = tuple((tilt @ turn).ravel())
image = read_image(os.path.join(data, "head_mr_small/HeadMRVolume.mhd"))
nx, ny, nz = image.GetDimensions()
crop = np.ascontiguousarray(vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx)[14:26, 20:32, 16:28])
spacing = (4.0, 2.5, 3.0)
points = [(20, 0.0), (60, 0.3), (120, 0.9)]
got = volumetricao.ambient_occlusion(image_of(crop, spacing, direction), radius=3, method="exact rays",
                                     opacity=points)
compare("rotated image, spacing 4 x 2.5 x 3, R=3 voxels", got,
        reference(crop, spacing, direction, points, 3 * 2.5, 2.5))
finish("Exact Rays equals the reference ray caster on every scan")
