"""VolumetricAO from Python on the CT head phantom: a VTK pipeline, and the numpy functions
with scipy's conventions (arrays [z, y, x], sampling per array axis).

    PYTHONPATH=build/lib/python3.11/site-packages python3 Examples/python_volumetricao.py \\
        Data/ct_head_phantom/ct_head_phantom_128x128x136_int16.mha

(or pvpython; after `cmake --install build --prefix PREFIX`, PYTHONPATH=PREFIX/lib/python3.11/site-packages).
"""
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
from vtkmodules.vtkIOImage import vtkMetaImageReader

import volumetricao
from volumetricao import vtkVolumetricAmbientOcclusion

path = sys.argv[1] if len(sys.argv) > 1 else "Data/ct_head_phantom/ct_head_phantom_128x128x136_int16.mha"
reader = vtkMetaImageReader()
reader.SetFileName(path)

# 1. In a VTK pipeline: the filter adds a float32 point array "AmbientOcclusion".
ao = vtkVolumetricAmbientOcclusion()
ao.SetInputConnection(reader.GetOutputPort())
ao.SetMethod(vtkVolumetricAmbientOcclusion.HISTOGRAM_CDF)  # the default
ao.SetRadius(5)
ao.Update()
image = ao.GetOutput()
openness = vtk_to_numpy(image.GetPointData().GetArray("AmbientOcclusion"))
print("volumetricao %s: %s, %d voxels, AO mean %.3f" % (volumetricao.__version__, path, openness.size, openness.mean()))

# 2. numpy in, numpy out: the same numbers without a pipeline.
nx, ny, nz = image.GetDimensions()
ct = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx)  # [z, y, x]
sampling = image.GetSpacing()[::-1]                                         # (z, y, x), as scipy.ndimage
fast, info = volumetricao.ambient_occlusion(ct, radius=5, return_info=True)
print("numpy function equals the pipeline:", np.array_equal(fast, openness.reshape(ct.shape)), "- ran on", info)
exact = volumetricao.ambient_occlusion(ct[40:60], radius=5, method="Exact Box")
print("Histogram CDF vs Exact Box on 20 slices: RMSE %.4f"
      % np.sqrt(np.mean((volumetricao.ambient_occlusion(ct[40:60], radius=5) - exact) ** 2)))
world = volumetricao.ambient_occlusion(reader, radius=10.0, world_radius=True)   # a reader: its spacing
print("a 10 mm radius (vtkImageData input, shape %s): AO mean %.3f" % (world.shape, world.mean()))

# 3. Skylight of the bone by occlusion sweeping, in millimetres.
sky, distance = volumetricao.occlusion_sweeping(ct, iso_value=400.0, sampling=sampling)
print("occlusion sweeping: %.1f%% of the voxels inside the bone, skylight mean %.3f outside"
      % (100.0 * (distance < 0).mean(), sky[distance > 0].mean()))

# 4. The bone's surface: AO and a soft shadow per vertex, vertices in (z, y, x) order as
# skimage.measure.marching_cubes(ct, 400.0, spacing=sampling) returns them.
mc = vtkFlyingEdges3D()
mc.SetInputData(image)
mc.SetValue(0, 400.0)
mc.Update()
vertices = vtk_to_numpy(mc.GetOutput().GetPoints().GetData())[:, ::-1] - image.GetOrigin()[::-1]
bone_ao, shadow = volumetricao.isosurface_ambient_occlusion(ct, vertices, sampling=sampling, shadows=True,
                                                            light_direction=(1.0, -1.0, 0.0))
colours = volumetricao.shade(None, bone_ao, shadow=shadow)
print("bone surface: %d vertices, AO mean %.3f, lit %.1f%%, RGB %s" % (len(vertices), bone_ao.mean(),
                                                                      100.0 * (shadow > 0.5).mean(), colours.shape))
