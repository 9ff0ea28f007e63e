"""Under MPI, the volume filters on a reader that does not split (MetaImage and NRRD: the
whole volume on rank 0, an empty image on the others) give the serial numbers: each rank
fetches its piece and halo from the rank that holds it. Runs mpi_unsplit_run.py with
pvbatch serially and on 2 and 3 ranks (the CT head as MetaImage), serially and on 2 ranks
(the same voxels as a detached NRRD header), and compares every array of every result.
Usage: pvpython test_mpi_unsplit.py PLUGIN DATA_DIR OUT PVBATCH MPIEXEC"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import array_of, check, finish, read_image  # noqa: E402

import numpy as np  # noqa: E402

plugin, data_dir, out_dir, pvbatch, mpiexec = sys.argv[1:6]
here = os.path.dirname(os.path.abspath(__file__))
volume = os.path.join(data_dir, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha")
ARRAYS = {"histogram": ["AmbientOcclusion"], "gaussian": ["AmbientOcclusion", "Variance"],
          "smoothed": ["AmbientOcclusion"], "sweeping": ["AmbientOcclusion", "SignedDistance"]}
# The sweeping's slabs stop exchanging when no ghost moves by ConvergenceTolerance.
TOLERANCE = {"sweeping": 1e-4}


def nrrd_copy(path):
    """The MetaImage's voxels as raw int16 with a detached NRRD header; its path."""
    image = read_image(path)
    values = array_of(image, image.GetPointData().GetScalars().GetName()).astype("<i2")
    raw = os.path.join(out_dir, "unsplit_ct.raw")
    values.tofile(raw)
    header = os.path.join(out_dir, "unsplit_ct.nhdr")
    with open(header, "w") as f:
        f.write("NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nspacings: %r %r %r\n"
                "encoding: raw\nendian: little\ndata file: unsplit_ct.raw\n"
                % (image.GetDimensions() + image.GetSpacing()))
    return header


def run(ranks, volume=volume, label=""):
    prefix = os.path.join(out_dir, "unsplit%s_np%d" % (label, ranks))
    command = [pvbatch, os.path.join(here, "mpi_unsplit_run.py"), plugin, volume, prefix]
    if ranks > 1:
        command = [mpiexec, "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + command
    print("running: " + " ".join(command), flush=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_"))}
    result = subprocess.run(command, timeout=600, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True)
    print(result.stdout, flush=True)
    check(result.returncode == 0 and " ERR| " not in result.stdout,
          "%d rank(s): exit 0 and no error logged" % ranks, stop=True)
    return prefix


serial = run(1)
nrrd = nrrd_copy(volume)
for ranks, distributed in ((2, run(2)), (3, run(3)), (2, run(2, nrrd, "_nrrd"))):
    for name, arrays in ARRAYS.items():
        expected = read_image("%s_%s.pvti" % (serial, name))
        got = read_image("%s_%s.pvti" % (distributed, name))
        check(got.GetExtent() == expected.GetExtent(), "%s on %d ranks covers the whole extent" % (name, ranks))
        for array in arrays:
            a, b = array_of(expected, array), array_of(got, array)
            worst = float(np.abs(a - b).max()) if a.shape == b.shape else float("inf")
            check(worst <= TOLERANCE.get(name, 0.0), "%s %s on %d ranks%s equals serial (max |diff| %g)"
                  % (name, array, ranks, " from NRRD" if "nrrd" in distributed else "", worst))
finish("the volume filters on an unsplit reader equal serial on 2 and 3 ranks")
