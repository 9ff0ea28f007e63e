"""The Python package volumetricao (python3 or pvpython): it imports from the tree given,
carries the project's version, and its numpy helpers equal the VTK filters bit for bit.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_package.py SITE_PACKAGES_DIR VERSION"""
import os
import sys

site, version = sys.argv[1], sys.argv[2]
sys.path.insert(0, site)
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from volumetricao import (ambient_occlusion, occlusion_sweeping, vtkOcclusionSweeping,  # noqa: E402
                          vtkVolumetricAmbientOcclusion)
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402

failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what, flush=True)
    if not condition:
        failures.append(what)


check(os.path.realpath(volumetricao.__file__).startswith(os.path.realpath(site)),
      "volumetricao imported from %s (%s)" % (site, volumetricao.__file__))
check(volumetricao.__version__ == version, "volumetricao.__version__ %s == %s" % (volumetricao.__version__, version))


def filter_result(values, algorithm, names, spacing=(1.0, 1.0, 1.0)):
    image = vtkImageData()
    image.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    image.SetSpacing(*spacing)
    scalars = numpy_to_vtk(values.reshape(-1), deep=1)
    scalars.SetName("v")
    image.GetPointData().SetScalars(scalars)
    algorithm.SetInputData(image)
    algorithm.Update()
    return [vtk_to_numpy(algorithm.GetOutput().GetPointData().GetArray(n)).reshape(values.shape) for n in names]


rng = np.random.default_rng(7)
volumes = {
    "int16": (rng.integers(-300, 900, size=(19, 17, 23)) // 50 * 50).astype(np.int16),
    "uint8": rng.integers(0, 256, size=(12, 21, 16)).astype(np.uint8),
    "float32": rng.normal(size=(15, 14, 13)).astype(np.float32),
}
cases = [("Histogram CDF", vtkVolumetricAmbientOcclusion.HISTOGRAM_CDF, {}),
         ("Gaussian CDF", vtkVolumetricAmbientOcclusion.GAUSSIAN_CDF, {}),
         ("CDF Reconstruction", vtkVolumetricAmbientOcclusion.CDF_RECONSTRUCTION, {}),
         ("Exact Box", vtkVolumetricAmbientOcclusion.EXACT_BOX, {}),
         ("Histogram CDF", vtkVolumetricAmbientOcclusion.HISTOGRAM_CDF, {"query_smoothing": 1.5}),
         ("Gaussian CDF", vtkVolumetricAmbientOcclusion.GAUSSIAN_CDF, {"iso_value": 0.5})]
for kind, values in volumes.items():
    for name, method, extra in cases:
        helper = ambient_occlusion(values, radius=3, method=name, **extra)
        f = vtkVolumetricAmbientOcclusion()
        f.SetMethod(method)
        f.SetRadius(3)
        if "query_smoothing" in extra:
            f.SetQueryMode(vtkVolumetricAmbientOcclusion.SMOOTHED_VALUE)
            f.SetQuerySmoothing(extra["query_smoothing"])
        if "iso_value" in extra:
            f.SetQueryMode(vtkVolumetricAmbientOcclusion.ISO_VALUE)
            f.SetIsoValue(extra["iso_value"])
        (reference,) = filter_result(values, f, ["AmbientOcclusion"])
        check(helper.dtype == np.float32 and helper.shape == values.shape and np.array_equal(helper, reference),
              "%s %s %s: ambient_occlusion equals the filter bit for bit" % (kind, name, extra))
ao, variance = ambient_occlusion(volumes["int16"], radius=2.5, spacing=(0.5, 1.0, 2.0), world_radius=True, variance=True)
f = vtkVolumetricAmbientOcclusion()
f.SetRadius(2.5)
f.SetRadiusUnits(vtkVolumetricAmbientOcclusion.WORLD)
f.SetComputeVariance(True)
expected = filter_result(volumes["int16"], f, ["AmbientOcclusion", "Variance"], spacing=(0.5, 1.0, 2.0))
check(np.array_equal(ao, expected[0]) and np.array_equal(variance, expected[1]),
      "world radius on anisotropic spacing, with the variance: equal to the filter")

sweep_ao, distance = occlusion_sweeping(volumes["float32"], 0.3)
s = vtkOcclusionSweeping()
s.SetIsoValue(0.3)
expected = filter_result(volumes["float32"], s, ["AmbientOcclusion", "SignedDistance"])
check(np.array_equal(sweep_ao, expected[0]) and np.array_equal(distance, expected[1]),
      "occlusion_sweeping equals vtkOcclusionSweeping")

# Other byte orders, float16 and bool are converted: the result is the native array's.
native = volumes["int16"]
for what, other, same, iso in [(">i2 (big-endian)", native.astype(">i2"), native, 50),
                               (">f8 (big-endian)", native.astype(">f8"), native.astype(np.float64), 50),
                               ("float16", native.astype(np.float16), native.astype(np.float16).astype(np.float32), 50),
                               ("bool", native > 100, (native > 100).astype(np.uint8), 0.5)]:
    check(np.array_equal(ambient_occlusion(other, radius=2, method="Gaussian CDF"),
                         ambient_occlusion(same, radius=2, method="Gaussian CDF")),
          "%s: ambient_occlusion equals that of the native array" % what)
    distance = occlusion_sweeping(other, iso)[1]
    check(np.array_equal(distance, occlusion_sweeping(same, iso)[1]) and (distance < 0).any() and (distance > 0).any(),
          "%s: occlusion_sweeping equals that of the native array (a surface crosses it)" % what)

for what, call, error, word in [
        ("complex values", lambda: ambient_occlusion(volumes["int16"].astype(np.complex64)), ValueError, "complex"),
        ("an object array", lambda: ambient_occlusion(volumes["int16"].astype(object)), ValueError, "numeric"),
        ("radius 0", lambda: ambient_occlusion(volumes["int16"], radius=0), RuntimeError, "rounds to 0 voxels"),
        ("an unknown method", lambda: ambient_occlusion(volumes["int16"], method="Fast"), ValueError, "unknown method"),
        ("a 2-D array", lambda: ambient_occlusion(np.zeros((4, 4))), ValueError, "3-D array"),
        ("NaN values", lambda: ambient_occlusion(np.full((5, 5, 5), np.nan, np.float32), radius=1), RuntimeError,
         "NaN")]:
    try:
        call()
        check(False, "%s raises %s" % (what, error.__name__))
    except error as e:
        check(word in str(e), "%s raises %s naming it (%r): %s" % (what, error.__name__, word, str(e).splitlines()[-1][:100]))
print("FAILED" if failures else "all package checks passed")
sys.exit(1 if failures else 0)
