"""pvbatch --symmetric under mpiexec (or plain pvpython for one process): composite image
input. A volume is cut at random into boxes, the boxes dealt at random to the ranks (several
on some, none on others), and handed to the filters as a vtkPartitionedDataSet, a
vtkMultiBlockDataSet (some pieces with their own origin and extents from 0, as Catalyst
adaptors make them) and a vtkPartitionedDataSetCollection holding two volumes on different
grids. Each filter's output holds every input piece with the serial result of its own
volume on it: Volumetric AO (Gaussian CDF; Histogram CDF, whose thresholds come from the
whole volume), Occlusion Sweeping, the Variance Occlusion Map (level by level) and Ambient
Occlusion Shading (every block coloured over the whole data's range); Isosurface
AO and Probe Outside Surface of the pieces' contours (a composite surface) in the composite
volume give, on every block's points, the serial result in the whole volume (and refuse a
volume input that holds two volumes).
Prints "ok: ..." / "FAILED: ..." per check and ends normally either way: ctest judges the
output. Usage: [mpiexec -np N] pvbatch --symmetric mpi_composite.py PLUGIN SITE_PACKAGES"""
import os
import sys

import numpy as np

from paraview.simple import LoadPlugin
from vtkmodules.vtkCommonDataModel import (vtkImageData, vtkMultiBlockDataSet, vtkPartitionedDataSet,
                                           vtkPartitionedDataSetCollection)
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
from vtkmodules.vtkParallelCore import vtkMultiProcessController
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import check, errors_of, serial_surface_values  # noqa: E402

LoadPlugin(sys.argv[1], remote=False)
sys.path.insert(0, sys.argv[2])
import volumetricao  # noqa: E402

controller = vtkMultiProcessController.GetGlobalController()
rank = controller.GetLocalProcessId() if controller else 0
ranks = controller.GetNumberOfProcesses() if controller else 1


def field(nx, ny, nz, phase):
    z, y, x = np.mgrid[0:nz, 0:ny, 0:nx]
    return (np.sin(x / 5.0 + phase) + np.cos(y / 7.0) + 2.0 * np.sin(z / 4.0) + (x * y % 7) / 3.0).astype(np.float32)


# Two volumes on different grids: B's origin is half a voxel off A's lattice.
VOLUMES = {"A": (field(31, 27, 23, 0.0), (0.0, 0.0, 0.0)), "B": (field(19, 24, 21, 1.3), (0.5, 0.0, 0.0))}


def random_cuts(rng, shape, count):
    """`count` boxes (x0, x1, y0, y1, z0, z1, inclusive) that tile the volume."""
    nz, ny, nx = shape
    boxes = [[0, nx - 1, 0, ny - 1, 0, nz - 1]]
    while len(boxes) < count:
        box = boxes.pop(int(rng.integers(len(boxes))))
        axis = int(np.argmax([box[1] - box[0], box[3] - box[2], box[5] - box[4]]))
        lo, hi = box[2 * axis], box[2 * axis + 1]
        at = int(rng.integers(lo, hi))  # the first box ends at `at`
        first, second = list(box), list(box)
        first[2 * axis + 1], second[2 * axis] = at, at + 1
        boxes += [first, second]
    return boxes


def dealt(rng, count):
    """The rank of each piece: several on some ranks, none on the middle one of three."""
    owners = [0, ranks - 1] if ranks == 3 else list(range(ranks))
    return [owners[int(rng.integers(len(owners)))] for _ in range(count)]


def piece(name, box, own_origin):
    values, origin = VOLUMES[name]
    image = vtkImageData()
    if own_origin:  # extent from 0, the piece's corner as its origin
        image.SetExtent(0, box[1] - box[0], 0, box[3] - box[2], 0, box[5] - box[4])
        image.SetOrigin(origin[0] + box[0], origin[1] + box[2], origin[2] + box[4])
    else:
        image.SetExtent(box)
        image.SetOrigin(origin)
    array = numpy_to_vtk(np.ascontiguousarray(values[box[4]:box[5] + 1, box[2]:box[3] + 1, box[0]:box[1] + 1]).ravel(),
                         deep=1)
    array.SetName("f")
    image.GetPointData().SetScalars(array)
    return image


def composite(kind, seed):
    """The composite data set of this rank, and its leaves in traversal order as (volume, box)."""
    rng = np.random.default_rng(seed)
    names = ["A", "B"] if kind == "collection" else ["A"]
    cuts = {n: random_cuts(rng, VOLUMES[n][0].shape, 7 if n == "A" else 4) for n in names}
    owners = {n: dealt(rng, len(cuts[n])) for n in names}
    leaves = []
    if kind == "collection":
        data = vtkPartitionedDataSetCollection()
        for i, n in enumerate(names):
            part = vtkPartitionedDataSet()
            for box, owner in zip(cuts[n], owners[n]):
                if owner == rank:
                    part.SetPartition(part.GetNumberOfPartitions(), piece(n, box, False))
                    leaves.append((n, box))
            data.SetPartitionedDataSet(i, part)
    elif kind == "partitioned":
        data = vtkPartitionedDataSet()
        for box, owner in zip(cuts["A"], owners["A"]):
            if owner == rank:
                data.SetPartition(data.GetNumberOfPartitions(), piece("A", box, False))
                leaves.append(("A", box))
    else:  # a multiblock tree, the same on every rank, a rank's pieces in its own blocks
        data = vtkMultiBlockDataSet()
        for i, (box, owner) in enumerate(zip(cuts["A"], owners["A"])):
            data.SetBlock(i, piece("A", box, i % 2 == 1) if owner == rank else None)
            if owner == rank:
                leaves.append(("A", box))
    return data, leaves


def leaves_of(data):
    found = []
    it = data.NewIterator()
    it.SkipEmptyNodesOn()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        found.append(it.GetCurrentDataObject())
        it.GoToNextItem()
    return found


def on_box(array, box):
    return vtk_to_numpy(array).reshape(box[5] - box[4] + 1, box[3] - box[2] + 1, box[1] - box[0] + 1)


AO = volumetricao.vtkVolumetricAmbientOcclusion
CASES = [
    ("Volumetric AO, Gaussian CDF", AO, dict(SetMethod=AO.GAUSSIAN_CDF, SetRadius=3),
     lambda v: volumetricao.ambient_occlusion(v, radius=3, method="gaussian cdf"), 1e-6),
    ("Volumetric AO, Histogram CDF", AO, dict(SetMethod=AO.HISTOGRAM_CDF, SetRadius=2),
     lambda v: volumetricao.ambient_occlusion(v, radius=2, method="histogram cdf"), 1e-6),
    ("Occlusion Sweeping", volumetricao.vtkOcclusionSweeping, dict(SetIsoValue=1.0),
     lambda v: volumetricao.occlusion_sweeping(v, 1.0)[0], 1e-6),
]

for seed, kind in enumerate(("partitioned", "multiblock", "collection")):
    data, leaves = composite(kind, 100 + seed)
    for name, make, settings, serial_of, tolerance in CASES:
        serial = {n: serial_of(VOLUMES[n][0]) for n in VOLUMES}
        f = make()
        for setter, value in settings.items():
            getattr(f, setter)(value)
        f.SetInputData(data)
        errors = errors_of(f)
        f.UpdatePiece(rank, ranks, 0)
        out = f.GetOutputDataObject(0)
        check(out.GetClassName() == data.GetClassName(), "%s, %s, rank %d of %d: a %s (got %s)"
              % (name, kind, rank, ranks, data.GetClassName(), out.GetClassName()))
        got_leaves = leaves_of(out)
        check(len(got_leaves) == len(leaves), "%s, %s, rank %d: %d pieces out (got %d)"
              % (name, kind, rank, len(leaves), len(got_leaves)))
        worst = 0.0
        for leaf, (n, box) in zip(got_leaves, leaves):
            ao = leaf.GetPointData().GetArray("AmbientOcclusion")
            if ao is None or leaf.GetPointData().GetArray("f") is None:
                worst = np.inf
                continue
            expected = serial[n][box[4]:box[5] + 1, box[2]:box[3] + 1, box[0]:box[1] + 1]
            worst = max(worst, float(np.abs(on_box(ao, box) - expected).max()))
        check(worst <= tolerance, "%s, %s, rank %d of %d, %d pieces: the serial AO of each piece's volume "
              "(max difference %.3g)" % (name, kind, rank, ranks, len(leaves), worst))
        check(not errors, "%s, %s, rank %d: no error (%s)" % (name, kind, rank, errors[:1]))

    # Ambient Occlusion Shading of the Volumetric AO output: every block coloured over one
    # range, the whole data's (the collection's two volumes are given one).
    scalar_range = (-1.0, 5.0) if kind == "collection" else (1.0, 0.0)
    ao = AO()
    ao.SetMethod(AO.GAUSSIAN_CDF)
    ao.SetRadius(3)
    ao.SetInputData(data)
    shading = volumetricao.vtkAmbientOcclusionShading()
    shading.SetScalarRange(*scalar_range)
    shading.SetInputConnection(ao.GetOutputPort())
    errors = errors_of(shading)
    shading.UpdatePiece(rank, ranks, 0)
    shaded = shading.GetOutputDataObject(0)
    check(len(leaves_of(shaded)) == len(leaves), "Ambient Occlusion Shading, %s, rank %d: %d blocks out (got %d)"
          % (kind, rank, len(leaves), len(leaves_of(shaded))))
    worst = 0.0
    for n in sorted({n for n, _ in leaves}):
        values = VOLUMES[n][0]
        serial_ao = AO()
        serial_ao.SetMethod(AO.GAUSSIAN_CDF)
        serial_ao.SetRadius(3)
        serial_ao.SetController(None)
        serial_ao.SetInputData(piece(n, [0, values.shape[2] - 1, 0, values.shape[1] - 1, 0, values.shape[0] - 1],
                                     False))
        serial_shading = volumetricao.vtkAmbientOcclusionShading()
        serial_shading.SetController(None)
        serial_shading.SetScalarRange(*scalar_range)
        serial_shading.SetInputConnection(serial_ao.GetOutputPort())
        serial_shading.Update()
        whole_rgba = vtk_to_numpy(serial_shading.GetOutput().GetPointData().GetArray("ShadedRGBA"))
        whole_rgba = whole_rgba.reshape(values.shape + (4,)).astype(int)
        for leaf, (m, box) in zip(leaves_of(shaded), leaves):
            rgba = leaf.GetPointData().GetArray("ShadedRGBA")
            if m != n:
                continue
            if rgba is None:
                worst = np.inf
                continue
            got = vtk_to_numpy(rgba).reshape(box[5] - box[4] + 1, box[3] - box[2] + 1, box[1] - box[0] + 1, 4)
            expected = whole_rgba[box[4]:box[5] + 1, box[2]:box[3] + 1, box[0]:box[1] + 1]
            worst = max(worst, float(np.abs(got.astype(int) - expected).max()))
    check(worst == 0, "Ambient Occlusion Shading, %s, rank %d of %d: every block's colours are the whole "
          "image's (max difference %g of 255)" % (kind, rank, ranks, worst))
    check(not errors, "Ambient Occlusion Shading, %s, rank %d: no error (%s)" % (kind, rank, errors[:1]))

    # The Variance Occlusion Map: the levels of each volume equal the serial ones.
    vom = volumetricao.vtkVarianceOcclusionMap()
    vom.SetNumberOfLevels(3)
    vom.SetInputData(data)
    errors = errors_of(vom)
    vom.UpdatePiece(rank, ranks, 0)
    blocks = vom.GetOutput()
    names = sorted({n for n, _ in leaves} | ({"A", "B"} if kind == "collection" else {"A"}))
    worst = 0.0
    for i, n in enumerate(names):
        levels = blocks.GetBlock(i) if len(names) > 1 else blocks
        reference = volumetricao.variance_occlusion_map(VOLUMES[n][0], levels=3)
        count = levels.GetNumberOfBlocks() if levels else 0
        check(count == 3, "Variance Occlusion Map, %s, volume %s, rank %d: 3 levels (got %d)" % (kind, n, rank, count))
        for level in range(count):
            image = levels.GetBlock(level)
            if not image or image.GetNumberOfPoints() == 0:
                continue
            e = image.GetExtent()
            expected = reference[level].mean[e[4]:e[5] + 1, e[2]:e[3] + 1, e[0]:e[1] + 1]
            got = on_box(image.GetPointData().GetArray("Mean"), e)
            worst = max(worst, float(np.abs(got - expected).max()) / max(1.0, float(np.abs(expected).max())))
    check(worst <= 1e-6, "Variance Occlusion Map, %s, rank %d of %d: the serial means (relative difference %.3g)"
          % (kind, rank, ranks, worst))
    check(not errors, "Variance Occlusion Map, %s, rank %d: no error (%s)" % (kind, rank, errors[:1]))
    # Isosurface AO and Probe Outside Surface of the pieces' contours, in the composite volume.
    contour = vtkFlyingEdges3D()
    contour.SetInputData(data)
    contour.SetValue(0, 1.0)
    contour.ComputeNormalsOn()
    contour.Update()
    surfaces = contour.GetOutputDataObject(0)
    sweep = volumetricao.vtkOcclusionSweeping()
    sweep.SetIsoValue(1.0)
    sweep.SetInputData(data)
    sweep.UpdatePiece(rank, ranks, 0)
    swept = sweep.GetOutputDataObject(0)
    for name, make, volume_of in (("Isosurface AO", volumetricao.vtkIsosurfaceAmbientOcclusion, lambda: data),
                                  ("Probe Outside Surface", volumetricao.vtkProbeOutsideSurface, lambda: swept)):
        f = make()
        f.SetInputData(0, surfaces)
        f.SetInputData(1, volume_of())
        errors = errors_of(f)
        f.UpdatePiece(rank, ranks, 0)
        out = f.GetOutputDataObject(0)
        if kind == "collection":
            check(any("holds 2 volumes" in e for e in errors),
                  "%s, %s, rank %d: a volume input with two volumes is refused" % (name, kind, rank))
            continue
        check(out.GetClassName() == surfaces.GetClassName(), "%s, %s, rank %d: a %s (got %s)"
              % (name, kind, rank, surfaces.GetClassName(), out.GetClassName()))
        # The reference: one process, each block's points in the whole volume.
        whole_volume = piece("A", [0, VOLUMES["A"][0].shape[2] - 1, 0, VOLUMES["A"][0].shape[1] - 1,
                                   0, VOLUMES["A"][0].shape[0] - 1], False)
        if name == "Probe Outside Surface":
            whole_sweep = volumetricao.vtkOcclusionSweeping()
            whole_sweep.SetIsoValue(1.0)
            whole_sweep.SetController(None)
            whole_sweep.SetInputData(whole_volume)
            whole_sweep.Update()
            whole_volume = whole_sweep.GetOutput()
        worst, points, blocks = 0.0, 0, 0
        for block, got_block in zip(leaves_of(surfaces), leaves_of(out)):
            if block.GetNumberOfPoints() == 0:
                continue
            expected = serial_surface_values(make, block, whole_volume, "AmbientOcclusion")
            array = got_block.GetPointData().GetArray("AmbientOcclusion")
            got = vtk_to_numpy(array) if array is not None else np.zeros(0)
            worst = max(worst, float(np.abs(got - expected).max()) if got.size == expected.size else np.inf)
            points += expected.size
            blocks += 1
        check(worst <= 1e-6, "%s, %s, rank %d of %d, %d blocks, %d points: the serial AO (max difference %.3g)"
              % (name, kind, rank, ranks, blocks, points, worst))
        check(not errors, "%s, %s, rank %d: no error (%s)" % (name, kind, rank, errors[:1]))
# Pieces with a ghost layer: each random box grown by one voxel along x where it can, the
# grown voxels flagged as duplicates (what ParaView's ghost cells generator makes). The AO is
# the whole image's at every point, and each piece keeps its own ghost flags.
rng = np.random.default_rng(7)
values = VOLUMES["A"][0]
nz, ny, nx = values.shape
boxes = random_cuts(rng, values.shape, 6)
owners = dealt(rng, len(boxes))
data = vtkPartitionedDataSet()
mine = []
for box, owner in zip(boxes, owners):
    if owner != rank:
        continue
    grown = [max(box[0] - 1, 0), min(box[1] + 1, nx - 1)] + box[2:]
    image = piece("A", grown, False)
    flags = np.zeros((grown[5] - grown[4] + 1, grown[3] - grown[2] + 1, grown[1] - grown[0] + 1), np.uint8)
    if grown[0] < box[0]:
        flags[:, :, 0] = 1
    if grown[1] > box[1]:
        flags[:, :, -1] = 1
    ghosts = numpy_to_vtk(flags.ravel(), deep=1)
    ghosts.SetName("vtkGhostType")
    image.GetPointData().AddArray(ghosts)
    data.SetPartition(data.GetNumberOfPartitions(), image)
    mine.append((grown, flags))
f = AO()
f.SetMethod(AO.GAUSSIAN_CDF)
f.SetRadius(3)
f.SetInputData(data)
errors = errors_of(f)
f.UpdatePiece(rank, ranks, 0)
serial = volumetricao.ambient_occlusion(values, radius=3, method="gaussian cdf")
worst, flags_kept = 0.0, True
for leaf, (grown, flags) in zip(leaves_of(f.GetOutputDataObject(0)), mine):
    ao = leaf.GetPointData().GetArray("AmbientOcclusion")
    got_flags = leaf.GetPointData().GetArray("vtkGhostType")
    flags_kept = flags_kept and got_flags is not None and np.array_equal(vtk_to_numpy(got_flags), flags.ravel())
    expected = serial[grown[4]:grown[5] + 1, grown[2]:grown[3] + 1, grown[0]:grown[1] + 1]
    worst = max(worst, float(np.abs(on_box(ao, grown) - expected).max()) if ao is not None else np.inf)
check(worst <= 1e-6, "pieces with a ghost layer, rank %d of %d, %d pieces: the whole image's AO at every point "
      "(max difference %.3g)" % (rank, ranks, len(mine), worst))
check(flags_kept, "pieces with a ghost layer, rank %d: each piece keeps its own ghost flags" % rank)
check(not errors, "pieces with a ghost layer, rank %d: no error (%s)" % (rank, errors[:1]))
print("rank %d of %d done" % (rank, ranks), flush=True)
