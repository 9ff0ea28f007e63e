"""pvbatch (serial or under mpirun): the volume filters on a file whose reader does not
split it across ranks (MetaImage: rank 0 reads it whole, the others get an empty image),
each result written as a .pvti. Usage: pvbatch mpi_unsplit_run.py PLUGIN INPUT.mha OUT_PREFIX"""
import sys

from paraview.simple import *  # noqa: F401,F403

plugin, input_path, prefix = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())
reader = OpenDataFile(input_path)
runs = {
    "histogram": VolumetricAmbientOcclusion(Input=reader, Radius=6),
    "gaussian": VolumetricAmbientOcclusion(Input=reader, Radius=6, Method="Gaussian CDF", ComputeVariance=1),
    "smoothed": VolumetricAmbientOcclusion(Input=reader, Radius=4, Method="Exact Box",
                                           QueryMode="Smoothed Voxel Value"),
    "sweeping": OcclusionSweeping(Input=reader, IsoValue=-300.0, NumberOfIterations=50,
                                  ConvergenceTolerance=1e-4),
}
for name, proxy in runs.items():
    SaveData("%s_%s.pvti" % (prefix, name), proxy=proxy, DataMode="Binary")
