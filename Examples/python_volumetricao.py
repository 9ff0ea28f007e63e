"""VolumetricAO from VTK Python: a VTK pipeline and the numpy helper on the CT head phantom.

    PYTHONPATH=build/lib/python3.11/site-packages python3 Examples/python_volumetricao.py \
        Data/ct_head_phantom/ct_head_phantom_128x128x136_int16.mha

(or pvpython; after `cmake --install build --prefix PREFIX`, PYTHONPATH=PREFIX/lib/python3.11/site-packages).
"""
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
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
fast = volumetricao.ambient_occlusion(ct, radius=5)
exact = volumetricao.ambient_occlusion(ct[40:60], radius=5, method="Exact Box")
print("numpy helper equals the pipeline:", np.array_equal(fast, openness.reshape(ct.shape)))
print("Histogram CDF vs Exact Box on 20 slices: RMSE %.4f"
      % np.sqrt(np.mean((volumetricao.ambient_occlusion(ct[40:60], radius=5) - exact) ** 2)))
smooth = volumetricao.ambient_occlusion(ct, radius=5, query_smoothing=1.0)
print("with the smoothed query: AO mean %.3f" % smooth.mean())
