"""The filters follow time steps. A temporal source refills one array in place at each step
without marking it modified (what an in situ adaptor that shares the simulation's memory
does): Volumetric AO and Occlusion Sweeping give each step's own result, with the step's
time on the output; Isosurface AO gives each step's result and rebuilds its pyramid when
the volume's time changes, and only then (not when the same step is asked again, nor when
only the light moves). Usage: python3 test_time_steps.py SITE_PACKAGES"""
import os
import sys

import numpy as np

sys.path.insert(0, sys.argv[1])
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import volumetricao  # noqa: E402
from vao_test_utils import check, finish  # noqa: E402
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402
from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase  # noqa: E402
from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkImageData  # noqa: E402
from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as SDDP  # noqa: E402
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D  # noqa: E402

NX, NY, NZ = 30, 26, 22
TIMES = [0.0, 0.5, 1.0]


def field(t):
    z, y, x = np.mgrid[0:NZ, 0:NY, 0:NX]
    return (np.sin(x / 4.0 + 3.0 * t) + np.cos(y / 5.0 - t) + np.sin(z / 3.0)).astype(np.float32)


class Simulation(VTKPythonAlgorithmBase):
    """Time steps TIMES; one buffer, refilled in place, never marked modified."""

    def __init__(self):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1, outputType="vtkImageData")
        self.buffer = np.zeros(NX * NY * NZ, np.float32)
        self.array = numpy_to_vtk(self.buffer, deep=0)
        self.array.SetName("f")
        self.image = vtkImageData()
        self.image.SetExtent(0, NX - 1, 0, NY - 1, 0, NZ - 1)
        self.image.GetPointData().SetScalars(self.array)

    def RequestInformation(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        info.Set(SDDP.WHOLE_EXTENT(), 0, NX - 1, 0, NY - 1, 0, NZ - 1)
        info.Set(SDDP.TIME_STEPS(), TIMES, len(TIMES))
        info.Set(SDDP.TIME_RANGE(), [TIMES[0], TIMES[-1]], 2)
        return 1

    def RequestData(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        t = info.Get(SDDP.UPDATE_TIME_STEP()) if info.Has(SDDP.UPDATE_TIME_STEP()) else TIMES[0]
        self.buffer[:] = field(t).ravel()
        output = vtkImageData.GetData(outInfo)
        output.ShallowCopy(self.image)
        return 1


def time_of(data):
    info = data.GetInformation()
    return info.Get(vtkDataObject.DATA_TIME_STEP()) if info.Has(vtkDataObject.DATA_TIME_STEP()) else None


simulation = Simulation()

# Volumetric AO and Occlusion Sweeping: each step's own result, stamped with its time.
ao = volumetricao.vtkVolumetricAmbientOcclusion()
ao.SetMethod(ao.GAUSSIAN_CDF)
ao.SetRadius(3)
ao.SetInputConnection(simulation.GetOutputPort())
sweep = volumetricao.vtkOcclusionSweeping()
sweep.SetIsoValue(0.5)
sweep.SetInputConnection(simulation.GetOutputPort())
for t in [TIMES[1], TIMES[0], TIMES[2], TIMES[1]]:
    for name, f, reference in (
            ("Volumetric AO", ao, lambda v: volumetricao.ambient_occlusion(v, radius=3, method="gaussian cdf")),
            ("Occlusion Sweeping", sweep, lambda v: volumetricao.occlusion_sweeping(v, 0.5)[0])):
        f.UpdateTimeStep(t)
        out = f.GetOutputDataObject(0)
        got = vtk_to_numpy(out.GetPointData().GetArray("AmbientOcclusion")).reshape(NZ, NY, NX)
        difference = float(np.abs(got - reference(field(t))).max())
        check(difference <= 1e-6, "%s at t = %g: that step's AO (max difference %.3g)" % (name, t, difference))
        check(time_of(out) == t, "%s at t = %g: the output's time step is %s" % (name, t, time_of(out)))

# Isosurface AO: rebuilt when the volume's time changes, and only then.
contour = vtkFlyingEdges3D()
contour.SetInputConnection(simulation.GetOutputPort())
contour.SetValue(0, 0.5)
contour.ComputeNormalsOn()
iso = volumetricao.vtkIsosurfaceAmbientOcclusion()
iso.SetInputConnection(0, contour.GetOutputPort())
iso.SetInputConnection(1, simulation.GetOutputPort())
builds = iso.GetNumberOfPyramidBuilds()
for t, rebuilt in [(TIMES[0], True), (TIMES[2], True), (TIMES[2], False), (TIMES[0], True)]:
    iso.UpdateTimeStep(t)
    out = iso.GetOutput()
    got = vtk_to_numpy(out.GetPointData().GetArray("AmbientOcclusion"))
    # The reference: a fresh filter on a copy of that step's volume and surface.
    volume = vtkImageData()
    volume.DeepCopy(simulation.GetOutputDataObject(0))
    surface = contour.GetOutput().NewInstance()
    surface.DeepCopy(contour.GetOutput())
    fresh = volumetricao.vtkIsosurfaceAmbientOcclusion()
    fresh.SetInputData(0, surface)
    fresh.SetInputData(1, volume)
    fresh.Update()
    expected = vtk_to_numpy(fresh.GetOutput().GetPointData().GetArray("AmbientOcclusion"))
    difference = float(np.abs(got - expected).max()) if got.size == expected.size else np.inf
    check(difference <= 1e-6, "Isosurface AO at t = %g: that step's AO (max difference %.3g)" % (t, difference))
    now = iso.GetNumberOfPyramidBuilds()
    check((now == builds + 1) == rebuilt, "Isosurface AO at t = %g: the pyramid %s (builds %d -> %d)"
          % (t, "rebuilt" if rebuilt else "kept", builds, now))
    builds = now
# A light move at the same step keeps the pyramid.
iso.SetComputeShadows(True)
iso.SetLightDirection(0.0, 1.0, 0.0)
iso.UpdateTimeStep(TIMES[0])
check(iso.GetNumberOfPyramidBuilds() == builds, "Isosurface AO: a light move keeps the pyramid")
finish("time steps followed")
