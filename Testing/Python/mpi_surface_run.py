"""pvbatch (serial or under mpirun): contour the CT head's bone and shade it with
Isosurface Ambient Occlusion (AO and shadows), write a .pvtp (one piece per rank).
Normals come from the volume gradient (the filter's fallback), which every rank computes
from its piece of the volume and the reach around it, so they do not depend on the
decomposition.
Usage: pvbatch mpi_surface_run.py PLUGIN INPUT.vti OUT.pvtp"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import XML_OPTIONS, extent_logger  # noqa: E402

plugin, source_path, target = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())
# Two readers: the contour asks for this rank's piece, the filter for that piece grown by
# the reach of its finer levels; one shared output cannot hold both at once. A
# pass-through logs the extent the filter's volume input received (<OUT>.volume.<rank>).
pieces = XMLImageDataReader(FileName=[source_path])
volume = extent_logger(XMLImageDataReader(FileName=[source_path]), target + ".volume")
bone = Contour(Input=pieces, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[400.0], ComputeNormals=0)
shaded = IsosurfaceAmbientOcclusion(Input=bone, Volume=volume, ComputeShadows=1, LightDirection=[0.0, -1.0, 1.0])
shaded.Scalars = ["POINTS", "MetaImage"]
SaveData(target, proxy=shaded, **XML_OPTIONS)

# Probe Outside Surface: a Volumetric AO field (bit for bit the serial one on any piece)
# sampled 1.5 voxels outside the bone, from its own reader (<OUT>_probe.pvtp).
field = VolumetricAmbientOcclusion(Input=XMLImageDataReader(FileName=[source_path]), Method="Gaussian CDF", Radius=3)
field.Scalars = ["POINTS", "MetaImage"]
normals_bone = Contour(Input=pieces, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[400.0], ComputeNormals=1)
probed = ProbeOutsideSurface(Input=normals_bone, Volume=field, Orientation="Normals")
SaveData(target[:-len(".pvtp")] + "_probe.pvtp", proxy=probed, **XML_OPTIONS)

# The pyramid (Variance Occlusion Map), distributed: each rank computes the level voxels
# of its piece from its piece grown by the pyramid's reach. A pass-through writes, per
# rank, every level's extent and arrays (<OUT>.pyramid.<rank>.npz) and the extent the
# map received (<OUT>.pyramid.read.<rank>).
read = extent_logger(XMLImageDataReader(FileName=[source_path]), target + ".pyramid.read")
dump = ProgrammableFilter(Input=VarianceOcclusionMap(Input=read))
dump.Script = """
import numpy as np
from vtkmodules.vtkParallelCore import vtkMultiProcessController
from vtkmodules.util.numpy_support import vtk_to_numpy
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId() if controller else 0
blocks = self.GetInputDataObject(0, 0)
self.GetOutputDataObject(0).ShallowCopy(blocks)
arrays = {}
for l in range(blocks.GetNumberOfBlocks()):
    level = blocks.GetBlock(l)
    if level is None or level.GetNumberOfPoints() == 0:
        continue
    arrays["extent%d" % l] = np.array(level.GetExtent())
    for name in ("Mean", "Variance"):
        arrays["%s%d" % (name, l)] = vtk_to_numpy(level.GetPointData().GetArray(name))
np.savez(TARGET + ".pyramid.%d.npz" % rank, **arrays)
""".replace("TARGET", repr(target))
dump.UpdatePipeline()
