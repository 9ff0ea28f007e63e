"""The bytes each rank sends to the others (AmbientOcclusionBytesSent) when the ranks hold
pieces without ghost layers, as an in situ adaptor hands them over: each rank owns a z-slab
of PIECE voxels (fixed, so the volume grows with the ranks), given to the filters by a
vtkTrivialProducer with the whole extent. Runs itself under mpiexec for 2, 4 and 8 ranks
(oversubscribed) and prints, per filter, the largest and the mean bytes sent per rank, and
their ratio to 2 ranks. Each run also checks its AO against the serial numbers of the whole
volume (max difference).

Usage: python3 Benchmarks/halo_bytes.py PLUGIN SITE_PACKAGES [RANKS ...]
       (as a worker: mpiexec -np N pvbatch --symmetric Benchmarks/halo_bytes.py --worker PLUGIN
        SITE_PACKAGES)"""
import os
import subprocess
import sys

PIECE = (64, 64, 40)  # x, y, z voxels of a rank's slab; z stays the longest axis of the volume


def field(nx, ny, nz):
    import numpy as np
    z, y, x = np.mgrid[0:nz, 0:ny, 0:nx]
    return (np.sin(x / 6.0) + np.cos(y / 7.0) + 2.0 * np.sin(z / 5.0) + (x * y % 7) / 3.0).astype(np.float32)


def worker(plugin, site_packages):
    import numpy as np
    from paraview.simple import LoadPlugin
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
    from vtkmodules.vtkParallelCore import vtkMultiProcessController
    LoadPlugin(plugin, remote=False)
    sys.path.insert(0, site_packages)
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Testing", "Python"))
    import volumetricao
    from vao_test_utils import serial_surface_values

    controller = vtkMultiProcessController.GetGlobalController()
    rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()
    nx, ny, nz = PIECE[0], PIECE[1], PIECE[2] * ranks
    volume = field(nx, ny, nz)
    z0, z1 = rank * PIECE[2], (rank + 1) * PIECE[2] - 1
    image = vtkImageData()
    image.SetExtent(0, nx - 1, 0, ny - 1, z0, z1)
    values = numpy_to_vtk(np.ascontiguousarray(volume[z0:z1 + 1]).ravel(), deep=1)
    values.SetName("f")
    image.GetPointData().SetScalars(values)
    producer = vtkTrivialProducer()
    producer.SetOutput(image)
    producer.SetWholeExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)

    def sent(output):
        array = output.GetFieldData().GetArray("AmbientOcclusionBytesSent")
        return float(array.GetValue(0)) if array else float("nan")

    def image_difference(output, reference):
        e = output.GetExtent()
        got = vtk_to_numpy(output.GetPointData().GetArray("AmbientOcclusion"))
        got = got.reshape(e[5] - e[4] + 1, e[3] - e[2] + 1, e[1] - e[0] + 1)
        return float(np.abs(got - reference[e[4]:e[5] + 1, e[2]:e[3] + 1, e[0]:e[1] + 1]).max())

    AO = volumetricao.vtkVolumetricAmbientOcclusion
    rows = []
    for name, method, radius in (("Volumetric AO, Gaussian CDF R=5", AO.GAUSSIAN_CDF, 5),
                                 ("Volumetric AO, Histogram CDF R=5", AO.HISTOGRAM_CDF, 5)):
        f = AO()
        f.SetMethod(method)
        f.SetRadius(radius)
        f.SetInputConnection(producer.GetOutputPort())
        f.UpdatePiece(rank, ranks, 0)
        reference = volumetricao.ambient_occlusion(volume, radius=radius, method=name.split(", ")[1][:-4].lower())
        rows.append((name, sent(f.GetOutput()), image_difference(f.GetOutput(), reference)))
    sweep = volumetricao.vtkOcclusionSweeping()
    sweep.SetIsoValue(1.0)
    sweep.SetInputConnection(producer.GetOutputPort())
    sweep.UpdatePiece(rank, ranks, 0)
    rows.append(("Occlusion Sweeping", sent(sweep.GetOutput()),
                 image_difference(sweep.GetOutput(), volumetricao.occlusion_sweeping(volume, 1.0)[0])))
    vom = volumetricao.vtkVarianceOcclusionMap()
    vom.SetNumberOfLevels(4)
    vom.SetInputConnection(producer.GetOutputPort())
    vom.UpdatePiece(rank, ranks, 0)
    levels = volumetricao.variance_occlusion_map(volume, levels=4)
    worst = 0.0
    for level in range(vom.GetOutput().GetNumberOfBlocks()):
        part = vom.GetOutput().GetBlock(level)
        if part and part.GetNumberOfPoints():
            e = part.GetExtent()
            got = vtk_to_numpy(part.GetPointData().GetArray("Mean")).reshape(
                e[5] - e[4] + 1, e[3] - e[2] + 1, e[1] - e[0] + 1)
            worst = max(worst, float(np.abs(got - levels[level].mean[e[4]:e[5] + 1, e[2]:e[3] + 1,
                                                                      e[0]:e[1] + 1]).max()))
    rows.append(("Variance Occlusion Map, 4 levels", sent(vom.GetOutput()), worst))
    contour = vtkFlyingEdges3D()
    contour.SetInputConnection(producer.GetOutputPort())
    contour.SetValue(0, 1.0)
    contour.ComputeNormalsOn()
    iso = volumetricao.vtkIsosurfaceAmbientOcclusion()
    iso.SetInputConnection(0, contour.GetOutputPort())
    iso.SetInputConnection(1, producer.GetOutputPort())
    iso.UpdatePiece(rank, ranks, 0)
    whole = vtkImageData()
    whole.SetExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
    all_values = numpy_to_vtk(volume.ravel(), deep=1)
    all_values.SetName("f")
    whole.GetPointData().SetScalars(all_values)

    def surface_difference(f, make, name):
        """Max difference of `name` from one process's filter at the same points."""
        got = vtk_to_numpy(f.GetOutput().GetPointData().GetArray(name))
        expected = serial_surface_values(make, contour.GetOutput(), whole, name)
        return float(np.abs(got - expected).max()) if got.size == expected.size else float("inf")

    rows.append(("Isosurface AO (of each slab's contour)", sent(iso.GetOutput()),
                 surface_difference(iso, volumetricao.vtkIsosurfaceAmbientOcclusion, "AmbientOcclusion")))

    probe = volumetricao.vtkProbeOutsideSurface()
    probe.SetInputConnection(0, contour.GetOutputPort())
    probe.SetInputConnection(1, producer.GetOutputPort())
    probe.UpdatePiece(rank, ranks, 0)
    rows.append(("Probe Outside Surface (of each contour)", sent(probe.GetOutput()),
                 surface_difference(probe, volumetricao.vtkProbeOutsideSurface, "f")))

    values = np.array([r[1] for r in rows] + [r[2] for r in rows], dtype=np.float64)
    gathered = np.zeros(values.size * ranks)
    controller.AllGather(values, gathered, values.size)
    if rank == 0:
        table = gathered.reshape(ranks, values.size)
        for i, (name, _, _) in enumerate(rows):
            column = table[:, i]
            print("ROW|%s|%d|%.0f|%.0f|%.3g" % (name, ranks, column.max(), column.mean(),
                                               table[:, len(rows) + i].max()), flush=True)


def main():
    plugin, site_packages = sys.argv[1], sys.argv[2]
    counts = [int(r) for r in sys.argv[3:]] or [2, 4, 8]
    results = {}
    for ranks in counts:
        run = subprocess.run(["mpiexec", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks),
                              "pvbatch", "--symmetric", os.path.abspath(__file__), "--worker", plugin, site_packages],
                             capture_output=True, text=True,
                             env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
        for line in run.stdout.splitlines():
            if line.startswith("ROW|"):
                _, name, n, largest, mean, difference = line.split("|")
                results.setdefault(name, {})[int(n)] = (float(largest), float(mean), float(difference))
        if run.returncode != 0:
            print(run.stdout[-2000:], run.stderr[-2000:])
    print("piece %d x %d x %d voxels (float32) per rank; KiB sent per rank, largest / mean "
          "(ratio to %d ranks); max AO difference from serial" % (PIECE + (counts[0],)))
    for name, by in results.items():
        base = by.get(counts[0])
        cells = []
        for n in counts:
            if n in by:
                largest, mean, difference = by[n]
                cells.append("%d: %.0f / %.0f (%.2fx / %.2fx) %.2g" % (
                    n, largest / 1024, mean / 1024, largest / base[0] if base[0] else float("nan"),
                    mean / base[1] if base[1] else float("nan"), difference))
        print("%-40s %s" % (name, "   ".join(cells)))


if __name__ == "__main__":
    if sys.argv[1] == "--worker":
        worker(sys.argv[2], sys.argv[3])
    else:
        main()
