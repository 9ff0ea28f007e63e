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

# The pyramid (Variance Occlusion Map), fetched to the client: per level its size and
# the sums of Mean and Variance, for the test to compare with the serial run.
import json  # noqa: E402

from paraview import servermanager  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

pyramid = VarianceOcclusionMap(Input=whole)
fetched = servermanager.Fetch(pyramid)  # under MPI: one block per rank, each a pyramid
iterator = fetched.NewIterator()
iterator.InitTraversal()
summary = []
while not iterator.IsDoneWithTraversal():
    level = iterator.GetCurrentDataObject()
    iterator.GoToNextItem()
    if level.GetNumberOfPoints() == 0:
        continue  # the empty blocks of ranks > 0
    summary.append({"dims": list(level.GetDimensions()), "spacing": list(level.GetSpacing()),
                    "mean": float(vtk_to_numpy(level.GetPointData().GetArray("Mean")).astype("float64").sum()),
                    "variance": float(vtk_to_numpy(level.GetPointData().GetArray("Variance")).astype("float64").sum())})
with open(target + ".pyramid.json", "w") as f:
    json.dump(summary, f)
