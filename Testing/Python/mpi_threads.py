"""pvbatch under mpiexec: each rank runs Volumetric Ambient Occlusion on its piece with the
default NumberOfThreads and checks the threads it used (the output's field data
"AmbientOcclusionThreads"): the cores this process may use divided by the ranks on the
node, at least 1, never more than the cores. Prints "FAILED: ..." otherwise, and ends normally
either way (no finish()): ctest judges the output, and a rank ending with an error status would
have mpiexec stop the others before they print.
The expected count is worked out here from that rule: with --bind-to none every rank may
use every core, so each gets max(1, cores // ranks on the node); 1 on a 2-core machine
with 4 ranks. Usage: mpiexec --bind-to none -np N pvbatch --symmetric mpi_threads.py PLUGIN (every rank runs it)"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager
from vtkmodules.vtkParallelCore import vtkMultiProcessController

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check  # noqa: E402

plugin = sys.argv[1]
cores = len(os.sched_getaffinity(0))
on_node = int(os.environ.get("OMPI_COMM_WORLD_LOCAL_SIZE", "1"))
expected = max(1, cores // on_node)
LoadPlugin(plugin, remote=True, ns=globals())
controller = vtkMultiProcessController.GetGlobalController()
rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()
ao = VolumetricAmbientOcclusion(Input=Wavelet(WholeExtent=[0, 40, 0, 40, 0, 40]), Method="Gaussian CDF", Radius=2)
ao.UpdatePipeline()
output = ao.GetClientSideObject().GetOutputDataObject(0)
threads = output.GetFieldData().GetArray("AmbientOcclusionThreads")
used = threads.GetValue(0) if threads else None
print("rank %d of %d (%d on this node, %d cores): %s compute threads, %d points"
      % (rank, ranks, on_node, cores, used, output.GetNumberOfPoints()), flush=True)
check(ranks == on_node, "every rank on this node (%d ranks, %d on the node)" % (ranks, on_node))
check(used == expected, "rank %d used %s threads, expected %d" % (rank, used, expected))
