"""A small simulation that runs ParaView Catalyst in situ: a time-dependent field on a
NX x NY x NZ grid, each MPI rank owning a z-slab of it with no ghost layers, handed to the
Catalyst v2 script `pipeline.py` through `paraview.catalyst.bridge` at every step.

    mpiexec -np 3 pvbatch --symmetric simulation.py --output extracts [--steps 3]
    pvbatch simulation.py --output extracts            # one process

The plugin is loaded by the pipeline from $VAO_PLUGIN (the path of VolumetricAO.so) or, when
that is unset, by name from ParaView's plugin path ($PV_PLUGIN_PATH). The extracts land in
the --output folder; `posthoc.py` computes the same filters afterwards and compares."""
import argparse
import os

import numpy as np

NX, NY, NZ = 48, 44, 40
TIME_STEP = 0.25


def field(t):
    """The simulation's state at time t, [z, y, x]: a ring of blobs that turns and swells
    above a rippled floor (what the pipeline contours at 1.0)."""
    z, y, x = np.mgrid[0:NZ, 0:NY, 0:NX].astype(np.float32)
    state = 2.0 * np.exp(-(z - 6.0 - np.sin(x / 4.0) * np.cos(y / 5.0)) ** 2 / 8.0)  # the floor
    for k in range(6):
        angle = k * np.pi / 3.0 + 0.4 * t
        cx, cy, cz = NX / 2 + 12 * np.cos(angle), NY / 2 + 12 * np.sin(angle), 18.0 + 3.0 * np.sin(angle + t)
        radius = 5.0 + 0.8 * np.sin(k + t)
        state += 2.0 * np.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (2.0 * radius * radius))
    return state.astype(np.float32)


def slab(rank, ranks):
    """The z-planes [z0, z1] this rank owns (no ghost layer)."""
    return rank * NZ // ranks, (rank + 1) * NZ // ranks - 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", required=True, help="folder for the extracts")
    parser.add_argument("--steps", type=int, default=3)
    args = parser.parse_args()

    from paraview.catalyst import bridge
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkParallelCore import vtkMultiProcessController

    controller = vtkMultiProcessController.GetGlobalController()
    rank = controller.GetLocalProcessId() if controller else 0
    ranks = controller.GetNumberOfProcesses() if controller else 1
    os.environ["VAO_EXTRACTS"] = os.path.abspath(args.output)
    bridge.initialize()
    bridge.add_pipeline(os.path.join(os.path.dirname(os.path.abspath(__file__)), "pipeline.py"), 2)
    z0, z1 = slab(rank, ranks)
    for step in range(args.steps):
        t = (step + 1) * TIME_STEP  # after the producer's initial time 0
        piece = np.ascontiguousarray(field(t)[z0:z1 + 1])
        image = vtkImageData()
        image.SetExtent(0, NX - 1, 0, NY - 1, z0, z1)
        image.SetSpacing(1.0, 1.0, 1.0)
        values = numpy_to_vtk(piece.ravel(), deep=1)
        values.SetName("density")
        image.GetPointData().SetScalars(values)
        # The whole extent tells the pipeline that the ranks' slabs are pieces of one volume.
        bridge.coprocess(t, step, image, wholeExtent=[0, NX - 1, 0, NY - 1, 0, NZ - 1])
    bridge.finalize()


if __name__ == "__main__":
    main()
