"""pvbatch (serial or under mpirun): read a .vti (ParaView's decomposition: each rank's
reader reads the sub-extent asked of it) or a .pvti written in pieces (a partitioned
reader), chain every image filter of the plugin, write a .pvti (one piece per rank).

Pass-through recorders log, per rank, the extent each filter received from upstream
(`<OUT>.extents`: "label rank x0 x1 y0 y1 z0 z1"), for the test to check that no rank
received the whole volume. Usage: pvbatch mpi_run.py PLUGIN INPUT OUT.pvti"""
import sys

from paraview.simple import *  # noqa: F401,F403

plugin, source, target = sys.argv[1:4]
LoadPlugin(plugin, remote=True, ns=globals())
log_path = target + ".extents"
open(log_path, "w").close()


def recorder(upstream, label):
    """Passes its input on unchanged and appends the extent it received to the log."""
    f = ProgrammableFilter(Input=upstream)
    f.Script = """
from vtkmodules.vtkParallelCore import vtkMultiProcessController
controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId() if controller else 0
data = self.GetInputDataObject(0, 0)
self.GetOutputDataObject(0).ShallowCopy(data)
with open(%r, "a") as log:
    log.write("%s %%d %%s\\n" %% (rank, " ".join(str(e) for e in data.GetExtent())))
""" % (log_path, label)
    return f


if source.endswith(".pvti"):
    reader = XMLPartitionedImageDataReader(FileName=[source])  # .pvti
else:
    reader = XMLImageDataReader(FileName=[source])
reader.PointArrayStatus = ["MetaImage"]
current = recorder(reader, "local")
# Local filters: each rank needs its piece grown by the radius (10 + 5 + 7 + 2 = 24 voxels
# for the chain).
stages = [("Gaussian CDF", 10, "GaussianCDF"), ("CDF Reconstruction", 5, "CDFReconstruction"),
          ("Chebyshev", 7, "Chebyshev"), ("Exact Box", 2, "ExactBox")]
for method, radius, name in stages:
    current = VolumetricAmbientOcclusion(Input=current, Method=method, Radius=radius,
                                         OutputArrayName=name, ComputeVariance=(name == "GaussianCDF"))
    current.Scalars = ["POINTS", "MetaImage"]
# Occlusion sweeping is global: each rank sweeps a slab (plus one ghost layer) and the
# slabs exchange faces until they agree; converged, so that serial runs agree too.
current = OcclusionSweeping(Input=recorder(current, "sweeping"), IsoValue=400.0, NumberOfIterations=50,
                            ConvergenceTolerance=1e-4)
current.Scalars = ["POINTS", "MetaImage"]
current = AmbientOcclusionShading(Input=current, AmbientOcclusionArray="GaussianCDF")
current.Scalars = "MetaImage"
SaveData(target, proxy=current, DataMode="Binary")

# A local filter asked directly for the writer's pieces (ParaView's decomposition of the
# output, with ghost levels grown by the radius): each rank needs its piece + 10 voxels.
direct = VolumetricAmbientOcclusion(Input=recorder(reader, "piece"), Method="Gaussian CDF", Radius=10,
                                    OutputArrayName="Direct")
direct.Scalars = ["POINTS", "MetaImage"]
SaveData(target[:-len(".pvti")] + "_direct.pvti", proxy=direct, DataMode="Binary")
