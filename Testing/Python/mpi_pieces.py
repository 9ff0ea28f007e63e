"""pvbatch --symmetric under mpiexec: each rank owns a z-slab of a volume, without ghost
layers, handed to the filters by a vtkTrivialProducer (what an in situ adaptor does). With
the whole extent given to the producer, Volumetric AO (Gaussian CDF and Histogram CDF),
Occlusion Sweeping, the Variance Occlusion Map, Isosurface AO and Probe Outside Surface (of
each slab's contour) give the serial numbers, fetching only their reach from the neighbours; without it (each
rank's whole extent is its own slab) each refuses on every rank with an error that names the
whole extent, and outputs nothing, instead of results that are wrong at every slab's border.
Prints "ok: ..." / "FAILED: ..." per check and ends normally either way: ctest judges the
output. Usage: mpiexec -np N pvbatch --symmetric mpi_pieces.py PLUGIN SITE_PACKAGES"""
import os
import sys

import numpy as np

from paraview.simple import LoadPlugin
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkCommonExecutionModel import vtkTrivialProducer
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
from vtkmodules.vtkParallelCore import vtkMultiProcessController
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, errors_of, serial_surface_values  # noqa: E402

LoadPlugin(sys.argv[1], remote=False)
sys.path.insert(0, sys.argv[2])
import volumetricao  # noqa: E402

controller = vtkMultiProcessController.GetGlobalController()
rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()
nx, ny, nz = 34, 30, 29  # slabs of unequal thickness on 2 and 3 ranks
z, y, x = np.mgrid[0:nz, 0:ny, 0:nx]
volume = (np.sin(x / 5.0) + np.cos(y / 7.0) + 2.0 * np.sin(z / 4.0) + (x * y % 7) / 3.0).astype(np.float32)
z0, z1 = rank * nz // ranks, (rank + 1) * nz // ranks - 1


def slab_producer(whole):
    image = vtkImageData()
    image.SetExtent(0, nx - 1, 0, ny - 1, z0, z1)
    values = numpy_to_vtk(np.ascontiguousarray(volume[z0:z1 + 1]).ravel(), deep=1)
    values.SetName("f")
    image.GetPointData().SetScalars(values)
    producer = vtkTrivialProducer()
    producer.SetOutput(image)
    if whole:
        producer.SetWholeExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
    return producer


def piece_of(image, array, serial):
    """The output's array and the serial result on its extent."""
    e = image.GetExtent()
    got = vtk_to_numpy(array).reshape(e[5] - e[4] + 1, e[3] - e[2] + 1, e[1] - e[0] + 1)
    return got, serial[e[4]:e[5] + 1, e[2]:e[3] + 1, e[0]:e[1] + 1]


CASES = [
    ("Volumetric AO, Gaussian CDF", lambda: volumetricao.vtkVolumetricAmbientOcclusion(),
     dict(SetMethod=volumetricao.vtkVolumetricAmbientOcclusion.GAUSSIAN_CDF, SetRadius=3),
     lambda: volumetricao.ambient_occlusion(volume, radius=3, method="gaussian cdf"), 0.0),
    ("Volumetric AO, Histogram CDF", lambda: volumetricao.vtkVolumetricAmbientOcclusion(),
     dict(SetMethod=volumetricao.vtkVolumetricAmbientOcclusion.HISTOGRAM_CDF, SetRadius=2),
     lambda: volumetricao.ambient_occlusion(volume, radius=2, method="histogram cdf"), 0.0),
    ("Occlusion Sweeping", lambda: volumetricao.vtkOcclusionSweeping(), dict(SetIsoValue=1.0),
     lambda: volumetricao.occlusion_sweeping(volume, 1.0)[0], 1e-6),
]

for name, make, settings, serial_of, tolerance in CASES:
    serial = serial_of()
    for whole in (True, False):
        producer = slab_producer(whole)
        f = make()
        for setter, value in settings.items():
            getattr(f, setter)(value)
        f.SetController(controller)
        f.SetInputConnection(producer.GetOutputPort())
        errors = errors_of(f)
        f.UpdatePiece(rank, ranks, 0)
        out = f.GetOutput()
        ao = out.GetPointData().GetArray("AmbientOcclusion")
        if whole:
            check(ao is not None, "%s, rank %d of %d, slabs with the whole extent: an AmbientOcclusion array"
                  % (name, rank, ranks))
            if ao is not None:
                got, expected = piece_of(out, ao, serial)
                difference = float(np.abs(got - expected).max()) if got.size else 0.0
                check(difference <= tolerance, "%s, rank %d of %d: the serial AO (max difference %.3g)"
                      % (name, rank, ranks, difference))
            check(not errors, "%s, rank %d: no error (%s)" % (name, rank, errors[:1]))
        else:
            check(ao is None and out.GetNumberOfPoints() == 0,
                  "%s, rank %d of %d, slabs without the whole extent: no output" % (name, rank, ranks))
            check(any("disagree on the whole extent" in e for e in errors),
                  "%s, rank %d: an error says the ranks disagree on the whole extent" % (name, rank))

# The pyramid: the Variance Occlusion Map of the slabs equals the serial one, level by level.
serial_levels = volumetricao.variance_occlusion_map(volume, levels=3)
for whole in (True, False):
    producer = slab_producer(whole)
    vom = volumetricao.vtkVarianceOcclusionMap()
    vom.SetNumberOfLevels(3)
    vom.SetInputConnection(producer.GetOutputPort())
    errors = errors_of(vom)
    vom.UpdatePiece(rank, ranks, 0)
    blocks = vom.GetOutput()
    count = blocks.GetNumberOfBlocks() if blocks else 0
    if whole:
        check(count == 3, "Variance Occlusion Map, rank %d of %d: 3 levels (got %d)" % (rank, ranks, count))
        for level in range(count):
            image = blocks.GetBlock(level)
            mean = image.GetPointData().GetArray("Mean") if image else None
            if mean is None or image.GetNumberOfPoints() == 0:
                continue
            got, expected = piece_of(image, mean, serial_levels[level].mean)
            difference = float(np.abs(got - expected).max())
            check(difference <= 1e-6 * max(1.0, float(np.abs(expected).max())),
                  "Variance Occlusion Map level %d, rank %d: the serial mean (max difference %.3g)"
                  % (level, rank, difference))
    else:
        empty = all(not blocks.GetBlock(l) or blocks.GetBlock(l).GetNumberOfPoints() == 0 for l in range(count))
        check(empty, "Variance Occlusion Map, rank %d of %d, slabs without the whole extent: no levels"
              % (rank, ranks))
        check(any("disagree on the whole extent" in e for e in errors),
              "Variance Occlusion Map, rank %d: an error says the ranks disagree on the whole extent" % rank)
# Isosurface AO and Probe Outside Surface of each slab's own contour (a Contour in the same
# Catalyst pipeline): the serial values at those points, from the slab and its reach.
whole_image = vtkImageData()
whole_image.SetExtent(0, nx - 1, 0, ny - 1, 0, nz - 1)
values = numpy_to_vtk(volume.ravel(), deep=1)
values.SetName("f")
whole_image.GetPointData().SetScalars(values)
SURFACE_FILTERS = [("Isosurface AO", volumetricao.vtkIsosurfaceAmbientOcclusion, "AmbientOcclusion"),
                   ("Probe Outside Surface", volumetricao.vtkProbeOutsideSurface, "f")]
for name, make, array_name in SURFACE_FILTERS:
    for whole in (True, False):
        producer = slab_producer(whole)
        contour = vtkFlyingEdges3D()
        contour.SetInputConnection(producer.GetOutputPort())
        contour.SetValue(0, 1.0)
        contour.ComputeNormalsOn()
        f = make()
        if hasattr(f, "SetController"):
            f.SetController(controller)
        f.SetInputConnection(0, contour.GetOutputPort())
        f.SetInputConnection(1, producer.GetOutputPort())
        errors = errors_of(f)
        f.UpdatePiece(rank, ranks, 0)
        sampled = f.GetOutput().GetPointData().GetArray(array_name)
        if not whole:
            check(f.GetOutput().GetNumberOfPoints() == 0,
                  "%s, rank %d of %d, slabs without the whole extent: no output" % (name, rank, ranks))
            check(any("disagree on the whole extent" in e for e in errors),
                  "%s, rank %d: an error says the ranks disagree on the whole extent" % (name, rank))
            continue
        expected = serial_surface_values(make, contour.GetOutput(), whole_image, array_name)
        got = vtk_to_numpy(sampled) if sampled is not None else np.zeros(0)
        check(got.size == expected.size and expected.size > 0, "%s, rank %d of %d: %s on each of the slab "
              "contour's %d points" % (name, rank, ranks, array_name, expected.size))
        if got.size == expected.size:
            difference = float(np.abs(got - expected).max()) if got.size else 0.0
            check(difference <= 1e-6, "%s, rank %d of %d: the serial %s (max difference %.3g)"
                  % (name, rank, ranks, array_name, difference))
        check(not errors, "%s, rank %d: no error (%s)" % (name, rank, errors[:1]))
print("rank %d of %d done" % (rank, ranks), flush=True)
