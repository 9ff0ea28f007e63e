"""Exchange rounds of the distributed occlusion sweeping on the generated head phantom.

    mpiexec -np N pvbatch Benchmarks/mpi_sweeping_rounds.py PLUGIN [SIZE]

(as root: mpiexec --allow-run-as-root --oversubscribe). Sweeps the SIZE^3 phantom
(default 256) at iso -300 HU with NumberOfIterations 50 and ConvergenceTolerance 1e-4
and prints, on rank 0, "ROUNDS <ranks> <rounds>" (None when run serially)."""
import sys

from paraview.simple import *  # noqa: F401,F403

LoadPlugin(sys.argv[1], remote=True, ns=globals())
size = int(sys.argv[2]) if len(sys.argv) > 2 else 256
phantom = AmbientOcclusionHeadPhantom(Dimensions=[size, size, size])
sweep = OcclusionSweeping(Input=phantom, IsoValue=-300.0, NumberOfIterations=50, ConvergenceTolerance=1e-4)
sweep.Scalars = ["POINTS", "Density"]
report = ProgrammableFilter(Input=sweep)
report.Script = """
from vtkmodules.vtkParallelCore import vtkMultiProcessController
controller = vtkMultiProcessController.GetGlobalController()
data = self.GetInputDataObject(0, 0)
self.GetOutputDataObject(0).ShallowCopy(data)
rounds = data.GetFieldData().GetArray("SweepingExchangeRounds")
if controller.GetLocalProcessId() == 0:
    print("ROUNDS", controller.GetNumberOfProcesses(), rounds.GetValue(0) if rounds else None, flush=True)
"""
report.UpdatePipeline()
