"""pvpython: what Show() gives for each filter, as the GUI's Apply does (both go through
ParaView's pipeline controller): the AO, not an Outline.

- Volumetric AO and Occlusion Sweeping: a Slice coloured by their AO array (the one
  OutputArrayName names) with a grey map over [0, 1];
- Ambient Occlusion Shading: a Volume of its RGBA colours as they are (Map Scalars off,
  the alpha as opacity);
- Isosurface AO and Probe Outside Surface: the surface coloured by AmbientOcclusion.
A colour map that existed before (a user's edits) is left as it was, and a source of
another plugin keeps ParaView's own default.

Usage: pvpython test_representations.py PLUGIN DATA_DIR
Prints "FAILED: ..." and exits non-zero on a failure."""
import os
import sys

from paraview.simple import *  # noqa: F401,F403 (and the plugin's proxies, loaded below)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, finish  # noqa: E402

plugin, data_dir = sys.argv[1:3]
LoadPlugin(plugin, ns=globals())
ct = OpenDataFile(os.path.join(data_dir, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha"))
view = CreateRenderView()


def grey_unit_map(array):
    """Whether the array's colour map is grey from 0 at 0 to 1 at 1."""
    points = list(GetColorTransferFunction(array).RGBPoints)
    nodes = [points[i:i + 4] for i in range(0, len(points), 4)]
    return (len(nodes) >= 2 and nodes[0][0] == 0.0 and nodes[-1][0] == 1.0
            and all(n[1] == n[2] == n[3] for n in nodes) and nodes[0][1] == 0.0 and nodes[-1][1] == 1.0)


def shown(proxy, representation, array, what):
    display = Show(proxy, view)
    check(display.Representation == representation, "%s is shown as %s (got %s)"
          % (what, representation, display.Representation))
    check(list(display.ColorArrayName) == ["POINTS", array], "%s is coloured by %s (got %s)"
          % (what, array, list(display.ColorArrayName)))
    return display


ao = VolumetricAmbientOcclusion(Input=ct, Radius=4, OutputArrayName="AO radius 4")
shown(ao, "Slice", "AO radius 4", "Volumetric AO")
check(grey_unit_map("AO radius 4"), "Volumetric AO's new map is grey over [0, 1]")

sweep = OcclusionSweeping(Input=ct, IsoValue=-300.0)
shown(sweep, "Slice", "AmbientOcclusion", "Occlusion Sweeping")
check(grey_unit_map("AmbientOcclusion"), "Occlusion Sweeping's new map is grey over [0, 1]")

shading = AmbientOcclusionShading(Input=ao, AmbientOcclusionArray="AO radius 4")
display = shown(shading, "Volume", "ShadedRGBA", "Ambient Occlusion Shading")
check(display.MapScalars == 0, "the Shading's RGBA are its colours (Map Scalars off)")
opacity = list(GetOpacityTransferFunction("ShadedRGBA").Points)
check(opacity == [0.0, 0.0, 0.5, 0.0, 255.0, 1.0, 0.5, 0.0],
      "the Shading's alpha is its opacity, 0-255 to 0-1 (got %s)" % opacity)
check(GetColorTransferFunction("ShadedRGBA").AutomaticRescaleRangeMode == "Never",
      "the alpha's opacity map is not rescaled to the RGBA's magnitude")

# A map the user edited stays as it is (a custom range, locked as the GUI's dialog does).
edited = GetColorTransferFunction("AmbientOcclusion")
edited.ApplyPreset("Viridis (matplotlib)", True)
edited.AutomaticRescaleRangeMode = "Never"
edited.RescaleTransferFunction(0.25, 0.75)
before = list(edited.RGBPoints)
bone = Contour(Input=ct, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[400.0], ComputeNormals=1)
shaded = IsosurfaceAmbientOcclusion(Input=bone, Volume=ct)
shown(shaded, "Surface", "AmbientOcclusion", "Isosurface AO")
check(list(GetColorTransferFunction("AmbientOcclusion").RGBPoints) == before,
      "an existing AmbientOcclusion map keeps the user's edits (%s, now %s)" % (before, list(GetColorTransferFunction("AmbientOcclusion").RGBPoints)))

skin = Contour(Input=ct, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[-300.0], ComputeNormals=1)
probe = ProbeOutsideSurface(Input=skin, Volume=sweep)
shown(probe, "Surface", "AmbientOcclusion", "Probe Outside Surface")

# Other sources keep ParaView's defaults: the reader's image is an Outline, uncoloured.
reader = Show(ct, view)
check(reader.Representation == "Outline", "the reader's own output is still an Outline")


finish("every filter shows its AO at Show()")
