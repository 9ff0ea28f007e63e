"""pvbatch (serial or under mpirun): read an inline .vti, chain the filter with several
methods, write a .pvti (one piece per rank). Usage: pvbatch mpi_run.py PLUGIN INPUT.vti OUT.pvti"""
import sys

from paraview.simple import *  # noqa: F401,F403

plugin, source, target = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())
reader = XMLImageDataReader(FileName=[source])
reader.PointArrayStatus = ["MetaImage"]
stages = [("Gaussian CDF", 10, "GaussianCDF"), ("CDF Reconstruction", 5, "CDFReconstruction"),
          ("Chebyshev", 7, "Chebyshev"), ("Exact Box", 2, "ExactBox")]
current = reader
for method, radius, name in stages:
    current = VolumetricAmbientOcclusion(Input=current, Method=method, Radius=radius,
                                         OutputArrayName=name, ComputeVariance=(name == "GaussianCDF"))
    current.Scalars = ["POINTS", "MetaImage"]
# Occlusion sweeping is global: every rank sweeps the whole volume, keeps its piece.
current = OcclusionSweeping(Input=current, IsoValue=400.0)
current.Scalars = ["POINTS", "MetaImage"]
SaveData(target, proxy=current, DataMode="Binary")
