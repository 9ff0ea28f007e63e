"""pvbatch under mpirun: occlusion sweeping and Isosurface AO of a volume with one NaN
voxel in the last rank's slab. Every rank must report an error and finish (the ranks
agree before any exchange): none may wait forever for the one that stopped.
Usage: pvbatch mpi_bad_input_run.py PLUGIN INPUT.vti OUT_PREFIX"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import XML_OPTIONS  # noqa: E402

plugin, source_path, prefix = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())
sweep = OcclusionSweeping(Input=XMLImageDataReader(FileName=[source_path]), IsoValue=0.5)
sweep.Scalars = ["POINTS", "v"]
SaveData(prefix + "_sweep.pvti", proxy=sweep, **XML_OPTIONS)
surface = Contour(Input=XMLImageDataReader(FileName=[source_path]), ContourBy=["POINTS", "v"], Isosurfaces=[0.5])
shaded = IsosurfaceAmbientOcclusion(Input=surface, Volume=XMLImageDataReader(FileName=[source_path]))
shaded.Scalars = ["POINTS", "v"]
SaveData(prefix + "_iso.pvtp", proxy=shaded, **XML_OPTIONS)
print("finished", flush=True)
