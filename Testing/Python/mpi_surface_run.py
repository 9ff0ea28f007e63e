"""pvbatch (serial or under mpirun): contour the CT head's bone and shade it with
Isosurface Ambient Occlusion (AO and shadows), write a .pvtp (one piece per rank).
Normals come from the volume gradient (the filter's fallback), which every rank computes
from the whole volume, so they do not depend on the decomposition.
Usage: pvbatch mpi_surface_run.py PLUGIN INPUT.vti OUT.pvtp"""
import sys

from paraview.simple import *  # noqa: F401,F403

plugin, source, target = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())
# Two readers: the contour asks for this rank's piece, the filter for the whole volume;
# one shared output cannot hold both at once.
pieces = XMLImageDataReader(FileName=[source])
whole = XMLImageDataReader(FileName=[source])
bone = Contour(Input=pieces, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[400.0], ComputeNormals=0)
shaded = IsosurfaceAmbientOcclusion(Input=bone, Volume=whole, ComputeShadows=1, LightDirection=[0.0, -1.0, 1.0])
shaded.Scalars = "MetaImage"
SaveData(target, proxy=shaded, DataMode="Binary")
