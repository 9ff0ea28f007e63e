"""pvpython: Volumetric AO's Transfer Function method follows the opacity transfer function
the Color Map Editor edits. The filter takes GetOpacityTransferFunction(array) itself, so
that editing its points (a point moved, a midpoint or sharpness changed) re-executes the
filter with the new opacity, and an update with nothing changed does not. Ambient Occlusion
Shading takes the same functions (the view's colour and opacity) and follows their edits.

Each result is compared with the tests' own reference (vao_test_utils.opacity_openness): a
numpy box mean (cumulative sums, the box clipped to the volume) of the opacity from
vtkPiecewiseFunction.GetValue itself.

Exact Rays through the same function follows its edits too, and equals the numpy function.

Usage: pvpython test_transfer_function.py PLUGIN PACKAGE_DIR
Prints "FAILED: ..." and exits non-zero on a failure."""
import os
import sys

import numpy as np

# The Python package (for the numpy function), imported before any of the plugin's client-side
# objects is touched: Python would otherwise give their class the type of its wrapped base.
sys.path.insert(0, sys.argv[2])
import volumetricao  # noqa: E402
from paraview.simple import *  # noqa: F401,F403 (and the plugin's proxies, loaded below)
from paraview import servermanager
from vtkmodules.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish, opacity_openness  # noqa: E402

LoadPlugin(sys.argv[1], ns=globals())
RADIUS = 4


def fetch(proxy, name):
    data = servermanager.Fetch(proxy)
    dims = data.GetDimensions()
    return vtk_to_numpy(data.GetPointData().GetArray(name)).reshape(dims[2], dims[1], dims[0], -1).squeeze()


def reference(density, function):
    return opacity_openness(density, function, (RADIUS,) * 3)


head = AmbientOcclusionHeadPhantom(Dimensions=[48, 48, 48])
opacity = GetOpacityTransferFunction("Density")
# Soft tissue shown, bone (above 300 HU) transparent; ParaView's points are
# (value, opacity, midpoint, sharpness).
opacity.Points = [-1000.0, 0.0, 0.5, 0.0, -200.0, 0.3, 0.4, 0.6, 250.0, 0.3, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0]
ao = VolumetricAmbientOcclusion(Input=head, Method="Transfer Function", Radius=RADIUS, OpacityFunction=opacity)
ao.Scalars = ["POINTS", "Density"]
runs = []
ao.GetClientSideObject().AddObserver("StartEvent", lambda caller, event: runs.append(1))
function = opacity.GetClientSideObject()

ao.UpdatePipeline()
density = fetch(head, "Density")
first = fetch(ao, "AmbientOcclusion")
error = np.abs(first - reference(density, function)).max()
check(error <= 1e-6, "Transfer Function equals the box mean of GetValue (max difference %.3g)" % error)
check(len(runs) == 1, "the filter ran once (%d)" % len(runs))
ao.UpdatePipeline()
check(len(runs) == 1, "an update with nothing changed does not re-execute (%d runs)" % len(runs))

# The Color Map Editor's edits: a point moved, then a midpoint and sharpness changed.
for step, points in enumerate([
        [-1000.0, 0.0, 0.5, 0.0, -100.0, 0.8, 0.5, 0.0, 250.0, 0.3, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0],
        [-1000.0, 0.0, 0.5, 0.0, -100.0, 0.8, 0.2, 0.9, 250.0, 0.3, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0]]):
    before = fetch(ao, "AmbientOcclusion")
    opacity.Points = points
    ao.UpdatePipeline()
    check(len(runs) == 2 + step, "edit %d re-executed the filter (%d runs)" % (step + 1, len(runs)))
    after = fetch(ao, "AmbientOcclusion")
    error = np.abs(after - reference(density, function)).max()
    check(error <= 1e-6 and np.abs(after - before).max() > 1e-3,
          "edit %d: the AO changed (by up to %.3g) to the new reference (max difference %.3g)"
          % (step + 1, np.abs(after - before).max(), error))

# Shading with the view's functions: the alpha follows the opacity as it is edited.
colors = GetColorTransferFunction("Density")
shaded = AmbientOcclusionShading(Input=ao, ColorTransferFunction=colors, OpacityTransferFunction=opacity)
shaded.Scalars = ["POINTS", "Density"]
shaded.UpdatePipeline()
alpha = fetch(shaded, "ShadedRGBA")[..., 3]
bone = density > 300
check(bone.any() and (alpha[bone] == 0).all() and alpha[(density > -150) & (density < 200)].max() > 0,
      "ShadedRGBA's alpha is the opacity function's: bone transparent, soft tissue shown")
opacity.Points = [-1000.0, 0.0, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0, 400.0, 1.0, 0.5, 0.0]  # bone shown instead
shaded.UpdatePipeline()
alpha = fetch(shaded, "ShadedRGBA")[..., 3]
check(alpha[density > 400].min() > 0 and (alpha[density < 300] == 0).all(),
      "editing the opacity function re-shades (bone shown, soft tissue transparent)")

# Exact Rays through the same function: an edit re-executes it, and ParaView's result is
# the numpy function's (the package's own filter, given the same function) bit for bit.
small = AmbientOcclusionHeadPhantom(Dimensions=[20, 20, 20])
rays = VolumetricAmbientOcclusion(Input=small, Method="Exact Rays", Radius=2, RayCount=24, OpacityFunction=opacity)
rays.Scalars = ["POINTS", "Density"]
ray_runs = []
rays.GetClientSideObject().AddObserver("StartEvent", lambda caller, event: ray_runs.append(1))
small_density = fetch(small, "Density")
spacing = servermanager.Fetch(small).GetSpacing()
for step, points in enumerate([[-1000.0, 0.0, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0, 400.0, 1.0, 0.5, 0.0],
                               [-1000.0, 0.0, 0.5, 0.0, -100.0, 0.8, 0.2, 0.9, 250.0, 0.3, 0.5, 0.0]]):
    opacity.Points = points
    rays.UpdatePipeline()
    got = fetch(rays, "AmbientOcclusion")
    expected = volumetricao.ambient_occlusion(small_density, radius=2, method="exact rays", ray_count=24,
                                              opacity=function, sampling=spacing[::-1])
    check(len(ray_runs) == step + 1 and np.array_equal(got, expected) and got.min() < 0.9,
          "Exact Rays, opacity %d: ran %d times, equals numpy's bit for bit (AO %.3f..%.3f)"
          % (step + 1, len(ray_runs), got.min(), got.max()))

# Rays likewise.
fast = VolumetricAmbientOcclusion(Input=small, Method="Rays", Radius=3, OpacityFunction=opacity)
fast.Scalars = ["POINTS", "Density"]
fast_runs = []
fast.GetClientSideObject().AddObserver("StartEvent", lambda caller, event: fast_runs.append(1))
for step, points in enumerate([[-1000.0, 0.0, 0.5, 0.0, 300.0, 0.0, 0.5, 0.0, 400.0, 1.0, 0.5, 0.0],
                               [-1000.0, 0.0, 0.5, 0.0, -100.0, 0.8, 0.2, 0.9, 250.0, 0.3, 0.5, 0.0]]):
    opacity.Points = points
    fast.UpdatePipeline()
    got = fetch(fast, "AmbientOcclusion")
    expected = volumetricao.ambient_occlusion(small_density, radius=3, method="rays", opacity=function,
                                              sampling=spacing[::-1])
    check(len(fast_runs) == step + 1 and np.array_equal(got, expected) and got.min() < 0.9,
          "Rays, opacity %d: ran %d times, equals numpy's bit for bit (AO %.3f..%.3f)"
          % (step + 1, len(fast_runs), got.min(), got.max()))

finish("transfer-function AO follows the opacity transfer function")
