"""pvpython: a new Ambient Occlusion Shading defaults its Scalars to an array of its own
input, whichever source was active when it was created.

paraview.simple connects a new filter to the active source first and to its Input
argument second; a selection that took its default from the first stays wrong. The case
of issue 45: Shading on the CT head's volume AO, then Contour + Isosurface AO + a second
Shading on the surface, created while the first Shading is active: the second's Scalars
was the first's output, ShadedRGBA, and the surface was not shaded.

The proxies named after DATA_DIR (e.g. VolumetricAmbientOcclusion) are checked the same
way on the volume: created on it while the first Shading is active.

Usage: pvpython test_shading_default.py PLUGIN DATA_DIR [PROXY ...]
Prints "FAILED: ..." and exits non-zero on a failure."""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (and the plugin's proxies, loaded below)
from paraview import servermanager
from vtkmodules.util.numpy_support import vtk_to_numpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish  # noqa: E402

plugin, data_dir = sys.argv[1:3]
volume_proxies = sys.argv[3:]
LoadPlugin(plugin, ns=globals())


def point_arrays(proxy):
    return set(proxy.PointData.keys())


ct = OpenDataFile(os.path.join(data_dir, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha"))
ct.UpdatePipeline()
(values,) = point_arrays(ct)
volume_ao = VolumetricAmbientOcclusion(Input=ct, Radius=3)
first = AmbientOcclusionShading(Input=volume_ao)
first.UpdatePipeline()
check("ShadedRGBA" in point_arrays(first), "the first Shading, on the volume, gives ShadedRGBA")

surface = Contour(Input=ct, ContourBy=["POINTS", values], Isosurfaces=[300.0], ComputeNormals=1)
for update_surface_first in (False, True):
    for active in ("the surface AO", "the first Shading"):
        iso = IsosurfaceAmbientOcclusion(Input=surface, Volume=ct)
        if update_surface_first:
            iso.UpdatePipeline()
        if active == "the first Shading":
            SetActiveSource(first)
        second = AmbientOcclusionShading(Input=iso)
        case = "second Shading created while %s is active (surface AO %s)" % (
            active, "updated before" if update_surface_first else "not updated yet")
        chosen = second.Scalars[1]
        iso.UpdatePipeline()
        check(chosen == "" or chosen in point_arrays(iso),
              "%s: Scalars %r is an array of its own input %s (or the active scalars)"
              % (case, chosen, sorted(point_arrays(iso))))
        second.UpdatePipeline()
        output = servermanager.Fetch(second)
        shaded = output.GetPointData().GetArray("ShadedRGB")
        points = iso.GetDataInformation().GetNumberOfPoints()
        picture = vtk_to_numpy(shaded) if shaded is not None else np.zeros((0, 3))
        check(shaded is not None and points > 1000 and len(picture) == points
              and len(np.unique(picture[:, 0])) > 10,
              "%s: ShadedRGB for each of the %d surface points, with %d grey levels (a picture, not an error)"
              % (case, points, len(np.unique(picture[:, 0]))))
        Delete(second)
        Delete(iso)

for name in volume_proxies:
    for update_volume_first in (False, True):
        SetActiveSource(first)
        proxy = globals()[name](Input=ct)
        if update_volume_first:
            proxy.UpdatePipeline()
        chosen = proxy.Scalars[1]
        proxy.UpdatePipeline()
        check(chosen in ("", values) and proxy.GetDataInformation().GetNumberOfPoints() > 0,
              "%s created on the volume while the first Shading is active: Scalars %r, an array of its own input"
              % (name, chosen))
        Delete(proxy)

finish("all Shading default checks passed")
