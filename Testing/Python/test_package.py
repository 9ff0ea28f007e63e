"""The Python package volumetricao (python3 or pvpython, build or install tree): it imports
from the tree given, carries the project's version, and each of its five numpy functions
equals its VTK filter bit for bit: random volumes of several dtypes, anisotropic sampling,
vtkImageData input, and for the isosurface AO a marching-cubes mesh with its vertices in
array order (z, y, x) as skimage.measure.marching_cubes gives them.
Prints "FAILED: ..." and exits non-zero on a failure.
Usage: python3 test_package.py SITE_PACKAGES_DIR VERSION"""
import os
import sys
import warnings

site, version = sys.argv[1], sys.argv[2]
sys.path.insert(0, site)
import numpy as np  # noqa: E402

import volumetricao  # noqa: E402
from volumetricao import (vtkAmbientOcclusionShading, vtkIsosurfaceAmbientOcclusion, vtkOcclusionSweeping,  # noqa: E402
                          vtkVarianceOcclusionMap, vtkVolumetricAmbientOcclusion)
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D  # noqa: E402

from vao_test_utils import check, finish, same  # noqa: E402


check(os.path.realpath(volumetricao.__file__).startswith(os.path.realpath(site)),
      "volumetricao imported from %s (%s)" % (site, volumetricao.__file__))
check(volumetricao.__version__ == version, "volumetricao.__version__ %s == %s" % (volumetricao.__version__, version))
public = {"ambient_occlusion", "occlusion_sweeping", "variance_occlusion_map", "isosurface_ambient_occlusion",
          "shade", "VolumetricAOWarning", "RunInfo", "Level"}
check(public <= set(volumetricao.__all__) and all(hasattr(volumetricao, n) for n in volumetricao.__all__)
      and not any(n.startswith("vtkCommon") for n in dir(volumetricao)),
      "__all__ lists the functions, the warning and the VTK classes; dir() shows no VTK modules")


def image_of(values, sampling=(1.0, 1.0, 1.0), **arrays):
    """A vtkImageData built by hand (not by the package): values [z, y, x], sampling (z, y, x)."""
    image = vtkImageData()
    image.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    image.SetSpacing(*reversed(sampling))
    scalars = numpy_to_vtk(values.reshape(-1), deep=1)
    scalars.SetName("v")
    image.GetPointData().SetScalars(scalars)
    for name, array in arrays.items():
        extra = numpy_to_vtk(array.reshape(values.size, -1) if array.ndim > 3 else array.reshape(-1), deep=1)
        extra.SetName(name)
        image.GetPointData().AddArray(extra)
    return image


def arrays_of(output, names, shape):
    result = []
    for name in names:
        array = output.GetPointData().GetArray(name)
        comps = array.GetNumberOfComponents()
        result.append(vtk_to_numpy(array).reshape(tuple(shape) + ((comps,) if comps > 1 else ())))
    return result


def filter_result(algorithm, image, names, shape):
    algorithm.SetInputData(image)
    algorithm.Update()
    return arrays_of(algorithm.GetOutput(), names, shape)


def smooth(shape, seed):
    """A smooth random volume: a sum of Gaussian blobs."""
    rng = np.random.default_rng(seed)
    z, y, x = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in shape], indexing="ij")
    volume = np.zeros(shape)
    for _ in range(6):
        c = rng.uniform(0.2, 0.8, 3) * shape
        volume += rng.uniform(50, 100) * np.exp(-((z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2)
                                                / (2 * rng.uniform(2, 4) ** 2))
    return volume


rng = np.random.default_rng(45)
volumes = {
    "int16": (rng.integers(-300, 900, size=(19, 17, 23)) // 50 * 50).astype(np.int16),
    "uint8": rng.integers(0, 256, size=(12, 21, 16)).astype(np.uint8),
    "float32": rng.normal(size=(15, 14, 13)).astype(np.float32),
    "float64": smooth((14, 18, 16), 1),
    "int32": rng.integers(-5, 5, size=(11, 13, 17)).astype(np.int32),
}
anisotropic = (2.0, 0.5, 1.25)

# 1. ambient_occlusion: every method and query, voxel and world radii.
V = vtkVolumetricAmbientOcclusion
cases = [("Histogram CDF", V.HISTOGRAM_CDF, {}), ("Gaussian CDF", V.GAUSSIAN_CDF, {}),
         ("CDF Reconstruction", V.CDF_RECONSTRUCTION, {}), ("Chebyshev", V.CHEBYSHEV, {}),
         ("Exact Box", V.EXACT_BOX, {}), ("exact_sphere", V.EXACT_SPHERE, {}),
         ("Histogram CDF", V.HISTOGRAM_CDF, {"query_smoothing": 1.5}),
         ("Gaussian CDF", V.GAUSSIAN_CDF, {"iso_value": 0.5, "erf": "winitzki"}),
         ("Histogram CDF", V.HISTOGRAM_CDF, {"world_radius": True, "number_of_bins": 17})]
for kind, values in volumes.items():
    for name, method, extra in cases:
        sampling = anisotropic if extra.get("world_radius") else (1.0, 1.0, 1.0)
        helper = volumetricao.ambient_occlusion(values, radius=3, method=name, sampling=sampling, backend="cpu",
                                                **extra)
        f = V()
        f.SetMethod(method)
        f.SetRadius(3)
        f.SetBackend(V.BACKEND_CPU)
        f.SetRadiusUnits(V.WORLD if extra.get("world_radius") else V.VOXELS)
        f.SetNumberOfBins(extra.get("number_of_bins", 64))
        f.SetErfApproximation(V.ERF_WINITZKI if "erf" in extra else V.ERF_EXACT)
        if "query_smoothing" in extra:
            f.SetQueryMode(V.SMOOTHED_VALUE)
            f.SetQuerySmoothing(extra["query_smoothing"])
        if "iso_value" in extra:
            f.SetQueryMode(V.ISO_VALUE)
            f.SetIsoValue(extra["iso_value"])
        (reference,) = filter_result(f, image_of(values, sampling), ["AmbientOcclusion"], values.shape)
        check(same(helper, reference), "%s %s %s: ambient_occlusion equals the filter" % (kind, name, extra))
values = volumes["int16"]
ao, variance = volumetricao.ambient_occlusion(values, radius=2.5, sampling=anisotropic, world_radius=True,
                                              variance=True)
f = V()
f.SetRadius(2.5)
f.SetRadiusUnits(V.WORLD)
f.SetComputeVariance(True)
expected = filter_result(f, image_of(values, anisotropic), ["AmbientOcclusion", "Variance"], values.shape)
check(same(ao, expected[0]) and same(variance, expected[1]),
      "world radius on anisotropic sampling, with the variance (backend auto): equal to the filter")
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    old = volumetricao.ambient_occlusion(values, tuple(reversed(anisotropic)), 2.5, world_radius=True)
check(same(old, expected[0]) and [w.category for w in caught] == [DeprecationWarning],
      "spacing (x, y, z), positional as before, still works with a DeprecationWarning")
image = image_of(values, anisotropic)
check(same(volumetricao.ambient_occlusion(image, radius=2.5, world_radius=True), expected[0]),
      "a vtkImageData input: its spacing is taken, the result is shaped [z, y, x]")

# A transposed anisotropic volume gives the transposed result (counts: exact).
for name in ("Exact Box", "Histogram CDF"):
    direct = volumetricao.ambient_occlusion(values, radius=2.0, sampling=anisotropic, world_radius=True, method=name)
    turned = volumetricao.ambient_occlusion(values.transpose(2, 0, 1), radius=2.0, world_radius=True, method=name,
                                            sampling=(anisotropic[2], anisotropic[0], anisotropic[1]))
    check(same(turned, direct.transpose(2, 0, 1)), "%s: sampling follows the array's axes (transposed volume, "
          "transposed result)" % name)

# 2. occlusion_sweeping: every property.
S = vtkOcclusionSweeping
mask = [1, 0, 1, 1, 0, 1, 0, 1]
sweeps = [({}, {}), ({"inside_is_above": False, "iterations": 3, "tolerance": 1e-3},
                     {"SetInsideIsAbove": 0, "SetNumberOfIterations": 3, "SetConvergenceTolerance": 1e-3}),
          ({"geometry_term": True, "gamma": 2.0, "opacity": 0.7, "octant_mask": mask},
           {"SetUseGeometryTerm": 1, "SetGamma": 2.0, "SetOpacity": 0.7, "SetOctantMask": mask}),
          ({"octant_visibility": True}, {"SetOutputOctantVisibility": 1})]
for kind in ("float64", "int16", "uint8"):
    values = volumes[kind]
    iso = float(np.median(values))
    for options, setters in sweeps:
        result = volumetricao.occlusion_sweeping(values, iso, sampling=anisotropic, **options)
        s = S()
        s.SetIsoValue(iso)
        for setter, argument in setters.items():
            getattr(s, setter)(*(argument if isinstance(argument, list) else [argument]))
        names = ["AmbientOcclusion", "SignedDistance"]
        names += ["OctantVisibility"] if "octant_visibility" in options else []
        expected = filter_result(s, image_of(values, anisotropic), names, values.shape)
        check(len(result) == len(names) and all(same(a, b) for a, b in zip(result, expected)),
              "%s %s: occlusion_sweeping equals vtkOcclusionSweeping (%s)" % (kind, options, ", ".join(names)))

# 3. variance_occlusion_map: the levels' arrays, sampling and origin.
for kind, options in (("float64", {"levels": 3}), ("int16", {"levels": 2, "start_at_half_resolution": True})):
    values = volumes[kind]
    levels = volumetricao.variance_occlusion_map(values, sampling=anisotropic, **options)
    m = vtkVarianceOcclusionMap()
    m.SetNumberOfLevels(options["levels"])
    m.SetStartAtHalfResolution(options.get("start_at_half_resolution", False))
    m.SetInputData(image_of(values, anisotropic))
    m.Update()
    blocks = [m.GetOutput().GetBlock(i) for i in range(m.GetOutput().GetNumberOfBlocks())]
    equal = len(levels) == len(blocks) == options["levels"]
    for level, block in zip(levels, blocks):
        nx, ny, nz = block.GetDimensions()
        mean, var = arrays_of(block, ["Mean", "Variance"], (nz, ny, nx))
        equal = equal and same(level.mean, mean) and same(level.variance, var)
        equal = equal and level.sampling == tuple(reversed(block.GetSpacing()))
        equal = equal and level.origin == tuple(reversed(block.GetOrigin()))
    check(equal, "%s %s: variance_occlusion_map equals the filter's levels (arrays, sampling, origin in "
          "(z, y, x))" % (kind, options))

# 4. isosurface_ambient_occlusion on a marching-cubes mesh: the filter on the mesh as VTK
# has it, the function on its vertices and normals in (z, y, x) order (skimage's).
I = vtkIsosurfaceAmbientOcclusion
volume = smooth((30, 26, 34), 7)
sampling = (1.5, 0.75, 1.0)
for kind, values in (("float64", volume), ("float32", volume.astype(np.float32)),
                     ("int16", np.round(volume * 10).astype(np.int16))):
    image = image_of(values, sampling)
    mc = vtkFlyingEdges3D()
    mc.SetInputData(image)
    mc.SetValue(0, float(values.max()) * 0.4)
    mc.ComputeNormalsOn()
    mc.Update()
    mesh = mc.GetOutput()
    points = vtk_to_numpy(mesh.GetPoints().GetData())
    vertices = points[:, ::-1].copy()               # what skimage's marching_cubes(spacing=sampling) gives
    normals = vtk_to_numpy(mesh.GetPointData().GetNormals())[:, ::-1].copy()
    bare = vtkPolyData()
    bare.SetPoints(mesh.GetPoints())
    variants = [({}, {}, True), ({"shadows": True, "light_direction": (0.8, -0.3, 0.5)},
                                 {"SetComputeShadows": 1, "SetLightDirection": [0.5, -0.3, 0.8]}, True),
                ({"estimator": "gaussian cdf", "combine": "mean", "levels": 3, "offset_factor": 0.5},
                 {"SetEstimator": I.GAUSSIAN_CDF, "SetCombine": I.COMBINE_MEAN, "SetNumberOfLevels": 3,
                  "SetOffsetFactor": 0.5}, True),
                ({"iso_value": float(values.max()) * 0.4, "start_at_half_resolution": True, "shadows": True},
                 {"SetQueryMode": I.ISO_VALUE, "SetIsoValue": float(values.max()) * 0.4,
                  "SetStartAtHalfResolution": 1, "SetComputeShadows": 1}, True),
                ({"shadows": True}, {"SetComputeShadows": 1}, False)]
    for options, setters, with_normals in variants:
        result = volumetricao.isosurface_ambient_occlusion(values, vertices, normals if with_normals else None,
                                                           sampling=sampling, **options)
        result = result if isinstance(result, tuple) else (result,)
        f = I()
        for setter, argument in setters.items():
            getattr(f, setter)(*(argument if isinstance(argument, list) else [argument]))
        f.SetInputData(mesh if with_normals else bare)
        f.SetVolumeData(image)
        f.Update()
        names = ["AmbientOcclusion"] + (["Shadow"] if options.get("shadows") else [])
        expected = arrays_of(f.GetOutput(), names, (len(vertices),))
        check(len(vertices) > 500 and len(result) == len(names) and all(same(a, b) for a, b in zip(result, expected)),
              "%s, %d vertices, %s%s: isosurface_ambient_occlusion equals the filter"
              % (kind, len(vertices), options, "" if with_normals else ", normals from the gradient"))
as_double = volumetricao.isosurface_ambient_occlusion(values, vertices.astype(np.float64), normals.astype(np.float64),
                                                      sampling=sampling)
check(same(as_double, volumetricao.isosurface_ambient_occlusion(values, vertices, normals, sampling=sampling)),
      "float64 vertices and normals (read as VTK doubles) give what the same float32 ones give")
# Transposed: the volume's axes, the vertices' columns and the light turn together.
values = volume.astype(np.float32)
mc = vtkFlyingEdges3D()
mc.SetInputData(image_of(values, sampling))
mc.SetValue(0, float(values.max()) * 0.4)
mc.Update()
vertices = vtk_to_numpy(mc.GetOutput().GetPoints().GetData())[:, ::-1].copy()
light = (0.8, -0.3, 0.5)
direct = volumetricao.isosurface_ambient_occlusion(values, vertices, sampling=sampling, shadows=True,
                                                   light_direction=light)
order = (2, 0, 1)
turned = volumetricao.isosurface_ambient_occlusion(values.transpose(order), vertices[:, order], shadows=True,
                                                   sampling=[sampling[a] for a in order],
                                                   light_direction=[light[a] for a in order])
gap = max(float(np.abs(a - b).max()) for a, b in zip(direct, turned))
check(all(same(a, b) for a, b in zip(direct, turned)), "a transposed anisotropic volume, with its vertices and "
      "light transposed, gives the same AO and shadows (largest difference %g)" % gap)

# 5. shade: a volume (RGBA) and a surface (RGB).
H = vtkAmbientOcclusionShading
values = volumes["float64"]
ao, variance = volumetricao.ambient_occlusion(values, radius=3, variance=True)
for options, setters in (({}, {}), ({"color_preset": "bone", "scalar_range": (20, 90), "opacity_ramp": (30, 80),
                                     "ambient_intensity": 1.5, "gamma": 2.0},
                                    {"SetColorPreset": H.BONE, "SetScalarRange": [20, 90], "SetOpacityRamp": [30, 80],
                                     "SetAmbientIntensity": 1.5, "SetGamma": 2.0}),
                         ({"variance": variance, "variance_max": 40.0},
                          {"SetModulateOpacity": 1, "SetVarianceMax": 40.0})):
    rgba = volumetricao.shade(values, ao, **options)
    h = H()
    for setter, argument in setters.items():
        getattr(h, setter)(*(argument if isinstance(argument, list) else [argument]))
    (expected,) = filter_result(h, image_of(values, AmbientOcclusion=ao, Variance=variance), ["ShadedRGBA"],
                                values.shape)
    check(same(rgba, expected), "volume %s: shade equals vtkAmbientOcclusionShading (RGBA)"
          % ({k: v for k, v in options.items() if k != "variance"}))
iso = vtkIsosurfaceAmbientOcclusion()
iso.SetInputData(mesh)
iso.SetVolumeData(image)
iso.SetComputeShadows(True)
iso.Update()
surface = iso.GetOutput()
n = surface.GetNumberOfPoints()
surface_ao, shadow = arrays_of(surface, ["AmbientOcclusion", "Shadow"], (n,))
values_at = vtk_to_numpy(surface.GetPointData().GetScalars()).copy()
for what, given, options in (("no scalars (white)", None, {}),
                             ("scalars, cool to warm", values_at, {"color_preset": "cool to warm", "gamma": 1.7})):
    rgb = volumetricao.shade(given, surface_ao, shadow=shadow, **options)
    h = H()
    h.SetGamma(options.get("gamma", 1.0))
    h.SetColorPreset(H.COOL_TO_WARM if options else H.GRAYSCALE)
    copy = vtkPolyData()
    copy.ShallowCopy(surface)
    if given is None:
        copy.GetPointData().SetScalars(None)
    h.SetInputData(copy)
    h.Update()
    (expected,) = arrays_of(h.GetOutput(), ["ShadedRGB"], (n,))
    check(same(rgb, expected), "surface, %s, AO times Shadow: shade equals the filter (RGB per vertex)" % what)

finish("all package checks passed")
