"""Post hoc check of the in situ extracts: the same filters run afterwards, in one process,
on the simulation's field (simulation.field at each step's time), compared with what the
Catalyst pipeline wrote.

    python3 posthoc.py EXTRACTS_FOLDER [SITE_PACKAGES]

For each step: the Volumetric AO and Occlusion Sweeping extracts (ao_<step>.pvti,
sweeping_<step>.pvti, every rank's piece) against the numpy functions on the whole field; the shaded surface (surface_<step>.pvtp) against
Isosurface AO of the same points in the whole field; the picture (view_<step>.png) is not
blank. Prints one line per check and exits non-zero if any fails."""
import glob
import os
import sys

import numpy as np

if len(sys.argv) > 2:
    sys.path.insert(0, sys.argv[2])
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import volumetricao  # noqa: E402
from simulation import NX, NY, NZ, TIME_STEP, field  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkImageData  # noqa: E402
from vtkmodules.vtkIOImage import vtkPNGReader  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPImageDataReader, vtkXMLPPolyDataReader  # noqa: E402

folder = sys.argv[1]
failures = 0


def report(ok, what):
    global failures
    failures += 0 if ok else 1
    print(("ok: " if ok else "FAILED: ") + what, flush=True)


def read(reader_type, path):
    reader = reader_type()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


steps = sorted(int(os.path.basename(p)[3:9]) for p in glob.glob(os.path.join(folder, "ao_*.pvti")))
report(len(steps) > 0, "%d steps extracted in %s" % (len(steps), folder))
for step in steps:
    t = (step + 1) * TIME_STEP
    values = field(t)

    # Volumetric AO: every voxel of the assembled extract.
    # The float field's box sums round differently wherever they start (a rank's piece, a
    # thread's slices): in nearly flat boxes the serial AO itself moves that much between
    # thread counts, which bounds the agreement there (docs/distributed.md).
    image = read(vtkXMLPImageDataReader, os.path.join(folder, "ao_%06d.pvti" % step))
    expected = volumetricao.ambient_occlusion(values, radius=4, method="gaussian cdf", threads=1)
    spread = float(np.abs(volumetricao.ambient_occlusion(values, radius=4, method="gaussian cdf", threads=3)
                          - expected).max())
    array = image.GetPointData().GetArray("AmbientOcclusion")
    if array is None or image.GetDimensions() != (NX, NY, NZ):
        report(False, "step %d: the AO extract holds the %d x %d x %d field with AmbientOcclusion"
               % (step, NX, NY, NZ))
    else:
        got = vtk_to_numpy(array).reshape(NZ, NY, NX)
        difference = float(np.abs(got - expected).max())
        report(difference <= max(1e-6, 4.0 * spread), "step %d: Volumetric AO extract equals the serial AO "
               "(max difference %.3g; serial on 1 and 3 threads differ by %.3g)" % (step, difference, spread))

    # Occlusion Sweeping: every voxel, to the sweep's convergence tolerance.
    image = read(vtkXMLPImageDataReader, os.path.join(folder, "sweeping_%06d.pvti" % step))
    array = image.GetPointData().GetArray("AmbientOcclusion")
    if array is None or image.GetDimensions() != (NX, NY, NZ):
        report(False, "step %d: the sweeping extract holds the field with AmbientOcclusion" % step)
    else:
        got = vtk_to_numpy(array).reshape(NZ, NY, NX)
        difference = float(np.abs(got - volumetricao.occlusion_sweeping(values, 1.0)[0]).max())
        report(difference <= 1e-6, "step %d: Occlusion Sweeping extract equals the serial AO (max difference "
               "%.3g)" % (step, difference))

    # Isosurface AO: the extracted surface's points, shaded again in the whole field.
    surface = read(vtkXMLPPolyDataReader, os.path.join(folder, "surface_%06d.pvtp" % step))
    whole = vtkImageData()
    whole.SetExtent(0, NX - 1, 0, NY - 1, 0, NZ - 1)
    scalars = numpy_to_vtk(values.ravel(), deep=1)
    scalars.SetName("density")
    whole.GetPointData().SetScalars(scalars)
    serial = volumetricao.vtkIsosurfaceAmbientOcclusion()
    serial.SetController(None)
    serial.SetInputData(0, surface)
    serial.SetInputData(1, whole)
    serial.Update()
    got = surface.GetPointData().GetArray("AmbientOcclusion")
    want = serial.GetOutput().GetPointData().GetArray("AmbientOcclusion")
    if got is None or want is None or surface.GetNumberOfPoints() == 0:
        report(False, "step %d: the surface extract has points with AmbientOcclusion" % step)
    else:
        difference = float(np.abs(vtk_to_numpy(got) - vtk_to_numpy(want)).max())
        report(difference <= 1e-6, "step %d: Isosurface AO of the %d surface points equals the serial AO "
               "(max difference %.3g)" % (step, surface.GetNumberOfPoints(), difference))

    # The picture: written, and not one flat colour.
    picture = os.path.join(folder, "view_%06d.png" % step)
    if os.path.exists(picture):
        pixels = vtk_to_numpy(read(vtkPNGReader, picture).GetPointData().GetScalars())
        report(float(pixels.std()) > 5.0, "step %d: the picture shows something (pixel spread %.1f)"
               % (step, float(pixels.std())))
    else:
        report(False, "step %d: the picture %s was written" % (step, picture))
print("FAILED" if failures else "the extracts equal the post hoc run", flush=True)
sys.exit(1 if failures else 0)
