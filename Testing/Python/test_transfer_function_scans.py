"""Transfer Function AO on the shipped scans (and VAO_EXTRA_DATA_DIR's, when given) against
the tests' own reference (vao_test_utils.opacity_openness): the opacity of every voxel from
vtkPiecewiseFunction.GetValue itself (once per distinct value), its box mean in float64 by
cumulative sums with the box clipped to the volume. Random functions of 3-7 points inside and outside the scan's range
(midpoints, sharpness, clamping on and off), voxel and anisotropic world radii, the 8/16-bit
path (a table) and the float path (the CT in other units). Every voxel within 1e-5.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_transfer_function_scans.py SITE_PACKAGES_DIR DATA_DIR [EXTRA_DATA_DIR]"""
import os
import sys

sys.path.insert(0, sys.argv[1])
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction  # noqa: E402
from vtkmodules.vtkIOImage import vtkMetaImageReader, vtkNrrdReader  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLImageDataReader  # noqa: E402

from vao_test_utils import check, finish, opacity_openness  # noqa: E402

SCANS = ["ct_head_phantom/ct_head_phantom_128x128x136_int16.mha", "lidc2_ct_chest/LIDC2_256x256x133_uint8.mha",
         "headsq/headsq_64x64x93_int16.vti", "head_mr_small/HeadMRVolume.mhd",
         "engine/engine_256x256x128_uint8_zfp8.mha", "tooth/tooth.nhdr"]


def volume_of(path):
    """[z, y, x] values of a scan, or None when it is not there or not readable here."""
    if not os.path.exists(path):
        return None
    reader = {".vti": vtkXMLImageDataReader, ".nhdr": vtkNrrdReader}.get(os.path.splitext(path)[1], vtkMetaImageReader)()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    nx, ny, nz = image.GetDimensions()
    values = vtk_to_numpy(image.GetPointData().GetScalars())
    return values.reshape(nz, ny, nx) if values.ndim == 1 else None


def random_function(rng, lo, hi):
    function = vtkPiecewiseFunction()
    function.SetClamping(int(rng.integers(2)))
    span = hi - lo
    for x in np.sort(rng.uniform(lo - 0.1 * span, hi + 0.1 * span, int(rng.integers(3, 8)))):
        sharpness = float(rng.choice([0.0, 1.0, rng.uniform()]))
        function.AddPoint(float(x), float(rng.uniform()), float(rng.uniform(0.05, 0.95)), sharpness)
    return function


rng = np.random.default_rng(46)
folders = sys.argv[2:]
tested = 0
for name in SCANS:
    values = next((v for v in (volume_of(os.path.join(f, name)) for f in folders) if v is not None), None)
    if values is None:
        print("not here: " + name)
        continue
    tested += 1
    lo, hi = float(values.min()), float(values.max())
    cases = [(values, random_function(rng, lo, hi), dict(radius=int(rng.integers(2, 7))), "voxels")]
    # Anisotropic world radius: sampling (z, y, x) = (2, 1, 0.5) and radius 4 are 2, 4, 8 voxels.
    cases.append((values, random_function(rng, lo, hi), dict(radius=4.0, world_radius=True,
                                                                sampling=(2.0, 1.0, 0.5)), "anisotropic"))
    # The float path: the same scan in other units (no table), a function in those units.
    scaled = (values.astype(np.float32) - np.float32(lo)) / np.float32(max(hi - lo, 1.0)) + np.float32(0.25)
    cases.append((scaled, random_function(rng, 0.25, 1.25), dict(radius=3), "float32"))
    for data, function, options, label in cases:
        got = volumetricao.ambient_occlusion(data, method="transfer function", opacity=function, **options)
        if options.get("world_radius"):
            radii = (2, 4, 8)
        else:
            radii = (options["radius"],) * 3
        expected = opacity_openness(data, function, radii)
        error = np.abs(got.astype(np.float64) - expected).max()
        check(error <= 1e-5 and expected.std() > 1e-3,
              "%s %s (%d points, clamping %d, radii %s): max |O_tf - reference| %.2g, the reference's "
              "spread %.3f" % (name, label, function.GetSize(), function.GetClamping(), radii, error, expected.std()))
check(tested >= 4, "%d scans tested" % tested)
finish("transfer-function AO equals its reference on the scans")
