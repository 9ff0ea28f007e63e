"""Distributed runs equal the serial run: converts the CT head phantom to an inline .vti
and to a .pvti written in 4 pieces, runs mpi_run.py serially and under
`mpirun -np N pvbatch` on both (ParaView's decomposition of one file, and a partitioned
reader), reads the .pvti pieces back and compares every array; checks from the logged
extents that no rank received the whole volume (the local filters: at most its piece
grown by the radii; occlusion sweeping: its slab and one ghost layer). Then the surface
filters. Usage: pvpython test_mpi.py PLUGIN DATA_DIR OUT PVBATCH MPIEXEC N..."""
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import array_of, check, finish, logged_extent, read_image  # noqa: E402

import numpy as np  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter  # noqa: E402
from vtkmodules.vtkIOParallelXML import vtkXMLPImageDataWriter  # noqa: E402

plugin, data_dir, out_dir, pvbatch, mpiexec = sys.argv[1:6]
rank_counts = [int(n) for n in sys.argv[6:]]
here = os.path.dirname(os.path.abspath(__file__))

ct = read_image(os.path.join(data_dir, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha"))
WHOLE = ct.GetExtent()
source = os.path.join(out_dir, "mpi_ct.vti")
writer = vtkXMLImageDataWriter()
writer.SetInputData(ct)
writer.SetDataModeToBinary()
writer.SetFileName(source)
writer.Write()
partitioned = os.path.join(out_dir, "mpi_ct_pieces.pvti")
pwriter = vtkXMLPImageDataWriter()
pwriter.SetInputData(ct)
pwriter.SetDataModeToBinary()
pwriter.SetNumberOfPieces(4)
pwriter.SetStartPiece(0)
pwriter.SetEndPiece(3)
pwriter.SetFileName(partitioned)
pwriter.Write()
check(len(ET.parse(partitioned).getroot().findall(".//Piece")) == 4, "the partitioned input has 4 pieces")

def run(ranks, script="mpi_run.py", extension="pvti", input_path=source, tag=None):
    if tag is None:
        tag = "pieces_" if input_path.endswith(".pvti") else ""
    target = os.path.join(out_dir, "mpi_ct_%s_%snp%d.%s" % (script[:-3], tag, ranks, extension))
    command = [pvbatch, os.path.join(here, script), plugin, input_path, target]
    if ranks > 1:
        command = [mpiexec, "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + command
    print("running: " + " ".join(command), flush=True)
    # pvpython initialised MPI as a singleton: its OMPI_/PMIX_ variables would make the
    # child mpiexec believe it runs inside that job.
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_"))}
    subprocess.run(command, check=True, timeout=600, env=env)
    return target


# Local filters: equal to serial bit for bit. Occlusion sweeping: equal to the converged
# serial run to the tolerance (1e-4 mm): the slabs stop exchanging when no ghost moves by it.
exact = ["GaussianCDF", "Variance", "CDFReconstruction", "Chebyshev", "ExactBox", "ShadedRGBA"]
converged = {"SignedDistance": 1e-3, "AmbientOcclusion": 1e-5}
names = exact + list(converged)
serial_target = run(1)
serial = read_image(serial_target)
reference = {name: array_of(serial, name) for name in names}
serial_histogram = read_image(serial_target[:-len(".pvti")] + "_histogram.pvti")
serial_tf = read_image(serial_target[:-len(".pvti")] + "_tf.pvti")
serial_rays = read_image(serial_target[:-len(".pvti")] + "_rays.pvti")
serial_fast = read_image(serial_target[:-len(".pvti")] + "_fastrays.pvti")
for data, name in ((serial_histogram, "Histogram"), (serial_histogram, "HistogramSmoothed"),
                   (serial_tf, "TransferFunction"), (serial_rays, "ExactRays"), (serial_fast, "Rays")):
    reference[name] = array_of(data, name)
    check(reference[name].size == 128 * 128 * 136 and reference[name].std() > 0.05, "serial %s is a real field" % name)
for name in names:
    values = reference[name]
    check(values.size % (128 * 128 * 136) == 0 and values.max() > values.min(), "serial %s is a real field" % name)
RADII = 10 + 5 + 7 + 2  # the chain of local filters


def inside(extent, bound):
    return all(extent[2 * a] >= bound[2 * a] and extent[2 * a + 1] <= bound[2 * a + 1] for a in range(3))


def grown(extent, r):
    return tuple(max(WHOLE[i], extent[i] - r) if i % 2 == 0 else min(WHOLE[i], extent[i] + r) for i in range(6))


# The 4-piece file on 2 ranks (two whole pieces each) is the even case that 4 ranks (one
# each) already covers; 3 ranks split it unevenly.
for input_path in (source, partitioned):
    kind = "partitioned .pvti" if input_path.endswith(".pvti") else "one .vti"
    for ranks in (rank_counts if input_path == source else [n for n in rank_counts if 4 % n or n == 4]):
        target = run(ranks, input_path=input_path)
        pieces = ET.parse(target).getroot().findall(".//Piece")
        extents = [tuple(int(v) for v in p.get("Extent").split()) for p in pieces]
        check(len(extents) == ranks, "%s np %d wrote %d pieces %s" % (kind, ranks, len(extents), extents))
        received = {(label, rank): logged_extent("%s.%s" % (target, label), rank)
                    for label in ("local", "sweeping", "piece", "histogram", "tf", "rays", "fastrays")
                    for rank in range(ranks)}
        for rank, piece in enumerate(extents):
            slab = received.get(("sweeping", rank))
            thickness = max(slab[2 * a + 1] - slab[2 * a] + 1 for a in range(3) if slab[2 * a:2 * a + 2] !=
                            WHOLE[2 * a:2 * a + 2]) if slab and slab != WHOLE else None
            check(thickness is not None and thickness <= 136 // ranks + 3,
                  "%s np %d rank %d: occlusion sweeping received the slab %s (its own and one ghost layer)"
                  % (kind, ranks, rank, slab), stop=slab is None)
            # The local chain feeds the sweeping: it was asked for the slab, so it needs the
            # slab grown by the radii.
            local = received.get(("local", rank))
            check(local is not None and local != WHOLE and inside(local, grown(slab, RADII)),
                  "%s np %d rank %d: the local filters received %s, not the whole volume, within the "
                  "extent they produce %s grown by %d" % (kind, ranks, rank, local, slab, RADII))

        def pieces_received(suffix, label, reach, what):
            """Checks that each rank's branch `label` read its written piece grown by
            `reach`, not the whole volume; returns the branch's output file."""
            path = target[:-len(".pvti")] + suffix
            pieces = [tuple(int(v) for v in p.get("Extent").split())
                      for p in ET.parse(path).getroot().findall(".//Piece")]
            for rank, piece in enumerate(pieces):
                asked = received.get((label, rank))
                check(asked is not None and asked != WHOLE and inside(asked, grown(piece, reach)),
                      "%s np %d rank %d: %s of the piece %s received %s (the piece grown by %d)"
                      % (kind, ranks, rank, what, piece, asked, reach))
            return path

        direct_target = pieces_received("_direct.pvti", "piece", 10, "Volumetric AO")
        histogram_target = pieces_received("_histogram.pvti", "histogram", 11, "Histogram CDF (R = 5 + 6)")
        histogram_run = read_image(histogram_target)
        for name in ("Histogram", "HistogramSmoothed"):
            difference = np.abs(array_of(histogram_run, name) - reference[name]).max()
            check(difference == 0.0, "%s np %d: %s (thresholds reduced over the ranks) equals serial "
                  "(max difference %.3g)" % (kind, ranks, name, difference))
        tf_target = pieces_received("_tf.pvti", "tf", 6, "Transfer Function AO")
        difference = np.abs(array_of(read_image(tf_target), "TransferFunction") - reference["TransferFunction"]).max()
        check(difference == 0.0, "%s np %d: Transfer Function AO equals serial (max difference %.3g)"
              % (kind, ranks, difference))
        rays_target = pieces_received("_rays.pvti", "rays", 2, "Exact Rays")
        difference = np.abs(array_of(read_image(rays_target), "ExactRays") - reference["ExactRays"]).max()
        check(difference == 0.0, "%s np %d: Exact Rays equals serial (max difference %.3g)"
              % (kind, ranks, difference))
        fast_target = pieces_received("_fastrays.pvti", "fastrays", 4, "Rays")
        difference = np.abs(array_of(read_image(fast_target), "Rays") - reference["Rays"]).max()
        check(difference == 0.0, "%s np %d: Rays equals serial (max difference %.3g)" % (kind, ranks, difference))
        difference = np.abs(array_of(read_image(direct_target), "Direct") - reference["GaussianCDF"]).max()
        check(difference == 0.0, "%s np %d: Volumetric AO of the pieces equals serial (max difference %.3g)"
              % (kind, ranks, difference))
        distributed = read_image(target)
        rounds = distributed.GetFieldData().GetArray("SweepingExchangeRounds")
        check(rounds is not None and rounds.GetValue(0) >= 2,
              "%s np %d: the slabs exchanged faces in %s rounds" % (kind, ranks, rounds and rounds.GetValue(0)))
        for name in names:
            difference = np.abs(array_of(distributed, name) - reference[name]).max()
            bound = converged.get(name, 0.0)
            check(difference <= bound, "%s np %d: %s equals serial (max difference %.3g, bound %g)"
                  % (kind, ranks, name, difference, bound))
# Isosurface Ambient Occlusion: the shaded bone surface, matched point by point.
from vtkmodules.vtkIOXML import vtkXMLPPolyDataReader  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402


def surface_arrays(path, names):
    """{point rounded to 1e-4: (the point's values of each array in names)} of a .pvtp."""
    reader = vtkXMLPPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    surface = reader.GetOutput()
    points = vtk_to_numpy(surface.GetPoints().GetData()).astype("float64")
    arrays = [vtk_to_numpy(surface.GetPointData().GetArray(name)) for name in names]
    return {tuple(np.round(p, 4)): values for p, values in zip(points, zip(*arrays))}


def shaded_points(path):
    return surface_arrays(path, ("AmbientOcclusion", "Shadow"))


def probed_points(path):
    return surface_arrays(path, ("AmbientOcclusion", "Normals"))


def pyramid_pieces(path, ranks):
    """Per level, the pieces [(extent, mean, variance)] of every rank (arrays shaped z, y,
    x), and the extent each rank's map received."""
    levels, read = {}, []
    for rank in range(ranks):
        read.append(logged_extent(path + ".pyramid.read", rank))
        data = np.load(path + ".pyramid.%d.npz" % rank)
        for key in data.files:
            if key.startswith("extent"):
                l = int(key[len("extent"):])
                e = tuple(int(v) for v in data[key])
                shape = (e[5] - e[4] + 1, e[3] - e[2] + 1, e[1] - e[0] + 1)
                levels.setdefault(l, []).append(
                    (e, data["Mean%d" % l].reshape(shape), data["Variance%d" % l].reshape(shape)))
    return levels, read


serial_path = run(1, "mpi_surface_run.py", "pvtp")
serial_surface = shaded_points(serial_path)
serial_levels, serial_read = pyramid_pieces(serial_path, 1)
check(sorted(serial_levels) == [0, 1, 2, 3] and all(len(p) == 1 and p[0][0][0] == 0 for p in serial_levels.values())
      and serial_read[0] == WHOLE, "serial pyramid: 4 levels %s" % [serial_levels[l][0][1].shape for l in range(4)],
      stop=True)
check(len(serial_surface) > 10000, "serial bone surface: %d points" % len(serial_surface))
whole_voxels = 128 * 128 * 136
for ranks in rank_counts:
    distributed_path = run(ranks, "mpi_surface_run.py", "pvtp")
    levels, read = pyramid_pieces(distributed_path, ranks)
    for rank, e in enumerate(read):
        voxels = (e[1] - e[0] + 1) * (e[3] - e[2] + 1) * (e[5] - e[4] + 1)
        check(e != WHOLE and voxels < whole_voxels, "np %d rank %d: the variance occlusion map read %s "
              "(its piece grown by the pyramid's reach), not the whole volume" % (ranks, rank, e))
    worst = 0.0
    for l in range(4):
        _, mean, variance = serial_levels[l][0]
        covered = np.zeros(mean.shape, dtype=bool)
        for e, m, v in levels.get(l, []):
            window = np.s_[e[4]:e[5] + 1, e[2]:e[3] + 1, e[0]:e[1] + 1]
            covered[window] = True
            worst = max(worst, float((np.abs(m - mean[window]) / np.maximum(1.0, np.abs(mean[window]))).max()),
                        float((np.abs(v - variance[window]) / np.maximum(1.0, np.abs(variance[window]))).max()))
        check(covered.all(), "np %d: the ranks' pieces of level %d cover it (%d voxels)" % (ranks, l, covered.size))
    check(worst <= 1e-6, "np %d: the distributed pyramid equals the serial one (largest relative "
          "difference %.3g)" % (ranks, worst))
    for rank in range(ranks):
        e = logged_extent(distributed_path + ".volume", rank)
        voxels = (e[1] - e[0] + 1) * (e[3] - e[2] + 1) * (e[5] - e[4] + 1)
        check(e != WHOLE and voxels < whole_voxels, "np %d rank %d: Isosurface AO read the volume %s (its piece "
              "and the reach of the finer levels), not the whole volume" % (ranks, rank, e))
    distributed = shaded_points(distributed_path)
    matched = [key for key in distributed if key in serial_surface]
    check(len(matched) >= 0.999 * len(distributed), "np %d: %d of %d surface points found in the serial surface"
          % (ranks, len(matched), len(distributed)), stop=not matched)
    worst = max(max(abs(distributed[k][0] - serial_surface[k][0]), abs(distributed[k][1] - serial_surface[k][1]))
                for k in matched)
    # The pieces' pyramids differ from the whole one by float rounding (their moments are
    # taken about another sampled mean): 1e-5 is a few of those roundings.
    check(worst <= 1e-5, "np %d: surface AO and Shadow equal serial (max difference %.3g)" % (ranks, worst))
    # Probe Outside Surface of a Volumetric AO field: equal to serial wherever its inputs
    # are. ParaView's Contour computes normals from its piece alone, so they differ from
    # the serial ones at piece faces (about 1% of the bone's points on 3 ranks).
    serial_probe, probe = (probed_points(p[:-len(".pvtp")] + "_probe.pvtp") for p in (serial_path, distributed_path))
    same = [k for k in probe if k in serial_probe and np.abs(probe[k][1] - serial_probe[k][1]).max() <= 1e-6]
    check(len(same) >= 0.95 * len(serial_probe), "np %d: %d of %d probed points have the serial normals"
          % (ranks, len(same), len(serial_probe)), stop=not same)
    worst = max(abs(probe[k][0] - serial_probe[k][0]) for k in same)
    check(worst == 0.0, "np %d: Probe Outside Surface equals serial where the normals do (max difference %.3g)"
          % (ranks, worst))
# The same head as an oriented volume (a direction matrix of 0.6 rad about (1, 2, 3)).
# Isosurface AO takes the surface in the frame where it lies on the volume's iso value
# (ParaView 5.11's Contour leaves it along the image's axes, newer filters turn it): its
# AO is the unturned head's point for point, and a distributed run equals the serial one.
def ordered_arrays(path):
    reader = vtkXMLPPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    data = reader.GetOutput().GetPointData()
    return [vtk_to_numpy(data.GetArray(name)) for name in ("AmbientOcclusion", "Shadow")]


axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
turning = np.eye(3) + np.sin(0.6) * cross + (1 - np.cos(0.6)) * cross @ cross
turned = vtkImageData()
turned.DeepCopy(ct)
turned.SetDirectionMatrix(*turning.ravel())
turned_path = os.path.join(out_dir, "mpi_ct_turned.vti")
writer.SetInputData(turned)
writer.SetFileName(turned_path)
writer.Write()
turned_serial = run(1, "mpi_surface_run.py", "pvtp", input_path=turned_path, tag="turned_")
plain_ao = ordered_arrays(serial_path)[0]
turned_ao = ordered_arrays(turned_serial)[0]
check(turned_ao.size == plain_ao.size and float(np.abs(turned_ao - plain_ao).max()) <= 1e-5,
      "oriented head: Isosurface AO equals the unturned head's at each of %d points (max difference %.3g)"
      % (plain_ao.size, float(np.abs(turned_ao - plain_ao).max()) if turned_ao.size == plain_ao.size else -1))
turned_surface = shaded_points(turned_serial)
ranks = max(rank_counts)
distributed = shaded_points(run(ranks, "mpi_surface_run.py", "pvtp", input_path=turned_path, tag="turned_"))
matched = [key for key in distributed if key in turned_surface]
worst = max([max(abs(distributed[k][0] - turned_surface[k][0]), abs(distributed[k][1] - turned_surface[k][1]))
             for k in matched] or [np.inf])
check(len(matched) >= 0.999 * len(distributed) and worst <= 1e-5,
      "oriented head, np %d: %d of %d points matched, AO and Shadow equal serial (max difference %.3g)"
      % (ranks, len(matched), len(distributed), worst))

# Bad input on one rank only: a NaN voxel in the last slab of a 40^3 sphere. Every rank
# errors and finishes (no rank waits for the one that stopped).
from vtkmodules.util.numpy_support import numpy_to_vtk  # noqa: E402
z, y, x = np.mgrid[0:40, 0:40, 0:40]
sphere = (np.sqrt((x - 20.0) ** 2 + (y - 20.0) ** 2 + (z - 20.0) ** 2) < 10).astype("f4")
sphere[38, 5, 5] = np.nan
bad = vtkImageData()
bad.SetDimensions(40, 40, 40)
values = numpy_to_vtk(sphere.ravel(), deep=1)
values.SetName("v")
bad.GetPointData().SetScalars(values)
bad_path = os.path.join(out_dir, "mpi_nan.vti")
writer.SetInputData(bad)
writer.SetFileName(bad_path)
writer.Write()
env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_"))}
command = [mpiexec, "--allow-run-as-root", "--oversubscribe", "-np", "2", pvbatch,
           os.path.join(here, "mpi_bad_input_run.py"), plugin, bad_path, os.path.join(out_dir, "mpi_nan")]
try:
    result = subprocess.run(command, capture_output=True, text=True, timeout=120, env=env)
    output = result.stdout + result.stderr
except subprocess.TimeoutExpired:
    output = None
check(output is not None, "a NaN in one rank's slab: the MPI run finished (no rank waits forever)", stop=True)
check("finished" in output and "NaN or infinite values" in output and
      "another process failed" in output,
      "the rank with the NaN names it, the other says another process failed")
finish("all MPI checks passed")
