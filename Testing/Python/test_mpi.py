"""Distributed runs equal the serial run: converts the CT head phantom to an inline .vti,
runs mpi_run.py serially and under `mpirun -np N pvbatch`, reads the .pvti pieces back
and compares every array. Usage: pvpython test_mpi.py PLUGIN SHARED OUT PVBATCH MPIEXEC N..."""
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import array_of, check, read_image  # noqa: E402

import numpy as np  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter  # noqa: E402

plugin, shared, out_dir, pvbatch, mpiexec = sys.argv[1:6]
rank_counts = [int(n) for n in sys.argv[6:]]
here = os.path.dirname(os.path.abspath(__file__))

ct = read_image(os.path.join(shared, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha"))
source = os.path.join(out_dir, "mpi_ct.vti")
writer = vtkXMLImageDataWriter()
writer.SetInputData(ct)
writer.SetDataModeToBinary()
writer.SetFileName(source)
writer.Write()


def run(ranks, script="mpi_run.py", extension="pvti"):
    target = os.path.join(out_dir, "mpi_ct_%s_np%d.%s" % (script[:-3], ranks, extension))
    command = [pvbatch, os.path.join(here, script), plugin, source, target]
    if ranks > 1:
        command = [mpiexec, "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + command
    print("running: " + " ".join(command), flush=True)
    # pvpython initialised MPI as a singleton: its OMPI_/PMIX_ variables would make the
    # child mpiexec believe it runs inside that job.
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_"))}
    subprocess.run(command, check=True, timeout=600, env=env)
    return target


names = ["GaussianCDF", "Variance", "CDFReconstruction", "Chebyshev", "ExactBox", "SignedDistance",
         "AmbientOcclusion"]
serial = read_image(run(1))
reference = {name: array_of(serial, name) for name in names}
for name in names:
    values = reference[name]
    check(values.size == 128 * 128 * 136 and values.max() > values.min(), "serial %s is a real field" % name)

for ranks in rank_counts:
    target = run(ranks)
    pieces = ET.parse(target).getroot().findall(".//Piece")
    extents = [tuple(int(v) for v in p.get("Extent").split()) for p in pieces]
    check(len(extents) == ranks, "np %d wrote %d pieces %s" % (ranks, len(extents), extents))
    check(all((e[1] - e[0] + 1) * (e[3] - e[2] + 1) * (e[5] - e[4] + 1) < 128 * 128 * 136 for e in extents),
          "np %d: no piece is the whole volume" % ranks)
    distributed = read_image(target)
    for name in names:
        difference = np.abs(array_of(distributed, name) - reference[name]).max()
        check(difference <= 1e-6, "np %d: %s equals serial (max difference %.3g)" % (ranks, name, difference))
# Isosurface Ambient Occlusion: the shaded bone surface, matched point by point.
from vtkmodules.vtkIOXML import vtkXMLPPolyDataReader  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402


def shaded_points(path):
    reader = vtkXMLPPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    surface = reader.GetOutput()
    points = vtk_to_numpy(surface.GetPoints().GetData()).astype("float64")
    ao = vtk_to_numpy(surface.GetPointData().GetArray("AmbientOcclusion"))
    shadow = vtk_to_numpy(surface.GetPointData().GetArray("Shadow"))
    return {tuple(np.round(p, 4)): (a, s) for p, a, s in zip(points, ao, shadow)}


def pyramid_summary(path):
    import json
    with open(path + ".pyramid.json") as f:
        return json.load(f)


serial_path = run(1, "mpi_surface_run.py", "pvtp")
serial_surface = shaded_points(serial_path)
serial_pyramid = pyramid_summary(serial_path)
check(len(serial_pyramid) == 4 and all(level is not None for level in serial_pyramid),
      "serial pyramid: 4 levels %s" % [level["dims"] for level in serial_pyramid])
check(len(serial_surface) > 10000, "serial bone surface: %d points" % len(serial_surface))
for ranks in rank_counts:
    distributed_path = run(ranks, "mpi_surface_run.py", "pvtp")
    fetched = pyramid_summary(distributed_path)
    # Fetch's transport prints the spacing with 6 digits under MPI: compare it loosely.
    same = len(fetched) == len(serial_pyramid) and all(
        f["dims"] == r["dims"] and f["mean"] == r["mean"] and f["variance"] == r["variance"] and
        all(abs(a - b) <= 1e-5 * b for a, b in zip(f["spacing"], r["spacing"]))
        for f, r in zip(fetched, serial_pyramid))
    check(same, "np %d: the fetched pyramid equals the serial one (sizes, sums of Mean and Variance)" % ranks)
    distributed = shaded_points(distributed_path)
    matched = [key for key in distributed if key in serial_surface]
    check(len(matched) >= 0.999 * len(distributed), "np %d: %d of %d surface points found in the serial surface"
          % (ranks, len(matched), len(distributed)))
    worst = max(max(abs(distributed[k][0] - serial_surface[k][0]), abs(distributed[k][1] - serial_surface[k][1]))
                for k in matched)
    check(worst <= 1e-6, "np %d: surface AO and Shadow equal serial (max difference %.3g)" % (ranks, worst))
print("all MPI checks passed")
