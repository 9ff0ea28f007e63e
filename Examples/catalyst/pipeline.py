"""Catalyst v2 script: ambient occlusion of the simulation's field at every step.

- Volumetric Ambient Occlusion (Gaussian CDF, radius 4 voxels) of the field, saved as a
  data extract `ao_<step>.pvti` (one piece per rank);
- Occlusion Sweeping of the field at 1.0, saved as `sweeping_<step>.pvti`;
- a Contour of the field at 1.0 with Isosurface Ambient Occlusion, saved as
  `surface_<step>.pvtp`;
- a picture of the shaded surface, `view_<step>.png`.

The simulation's ranks hand over their slabs without ghost layers: each filter fetches what
it needs from the neighbouring ranks, and the extracts equal a serial run (posthoc.py)."""
import os

from paraview import catalyst
from paraview.simple import (CreateExtractor, CreateView, Contour, GetColorTransferFunction, GhostCellsGenerator,
                             LoadDistributedPlugin, LoadPlugin, Show, TrivialProducer)

if os.environ.get("VAO_PLUGIN"):
    LoadPlugin(os.environ["VAO_PLUGIN"], remote=False, ns=globals())
else:
    LoadDistributedPlugin("VolumetricAO", remote=False, ns=globals())

# The simulation's grid, registered under the name the adaptor gives it ("input").
simulation = TrivialProducer(registrationName="input")

ao = VolumetricAmbientOcclusion(registrationName="AO", Input=simulation)  # noqa: F821 (from the plugin)
ao.Scalars = ["POINTS", "density"]
ao.Method = "Gaussian CDF"
ao.Radius = 4
ao.QueryMode = "Voxel Value"

# One ghost layer from the neighbours, so that the contour has no cracks between slabs.
ghosts = GhostCellsGenerator(registrationName="Ghosts", Input=simulation)
sweeping = OcclusionSweeping(registrationName="Sweeping", Input=simulation)  # noqa: F821
sweeping.Scalars = ["POINTS", "density"]
sweeping.IsoValue = 1.0

contour = Contour(registrationName="Surface", Input=ghosts)
contour.ContourBy = ["POINTS", "density"]
contour.Isosurfaces = [1.0]
contour.ComputeNormals = 1
shaded = IsosurfaceAmbientOcclusion(registrationName="ShadedSurface", Input=contour,  # noqa: F821
                                    Volume=simulation)

volume_extract = CreateExtractor("VTI", ao, registrationName="AOExtract")
volume_extract.Writer.FileName = "ao_{timestep:06d}.pvti"
volume_extract.Writer.DataMode = "Binary"  # inline: Debian 12's VTK 9.2 fails on appended data
sweeping_extract = CreateExtractor("VTI", sweeping, registrationName="SweepingExtract")
sweeping_extract.Writer.FileName = "sweeping_{timestep:06d}.pvti"
sweeping_extract.Writer.DataMode = "Binary"
surface_extract = CreateExtractor("VTP", shaded, registrationName="SurfaceExtract")
surface_extract.Writer.FileName = "surface_{timestep:06d}.pvtp"
surface_extract.Writer.DataMode = "Binary"

view = CreateView("RenderView")
view.ViewSize = [480, 360]
view.OrientationAxesVisibility = 0
view.CameraPosition = [-40.0, -70.0, 75.0]
view.CameraFocalPoint = [24.0, 22.0, 14.0]
view.CameraViewUp = [0.0, 0.0, 1.0]
display = Show(shaded, view)
display.ColorArrayName = ["POINTS", "AmbientOcclusion"]
display.LookupTable = GetColorTransferFunction("AmbientOcclusion")
display.LookupTable.ApplyPreset("Grayscale", True)
display.LookupTable.RescaleTransferFunction(0.0, 1.0)
image_extract = CreateExtractor("PNG", view, registrationName="ViewExtract")
image_extract.Writer.FileName = "view_{timestep:06d}.png"

options = catalyst.Options()
options.GlobalTrigger = "TimeStep"
options.ExtractsOutputDirectory = os.environ.get("VAO_EXTRACTS", "extracts")
