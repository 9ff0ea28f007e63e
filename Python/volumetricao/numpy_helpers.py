"""numpy in, numpy out: the filters run on an array without building a VTK pipeline.

Arrays are indexed ``[z, y, x]`` (C order, x fastest: how VTK stores image data and how
numpy arrays from ``vtk_to_numpy(...).reshape(nz, ny, nx)`` come). Integer and float
arrays in the machine's byte order are read in place; other byte orders (``>i2`` from a
big-endian raw file, say) and float16 are converted, bool is read as 0 and 1. Complex
and non-numeric arrays are refused. The results are float32 arrays of the same shape.
"""
import numpy as np

from vtkmodules.util.misc import calldata_type
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.util.vtkConstants import VTK_STRING
from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkCommonDataModel import vtkImageData

_METHODS = {
    "histogram cdf": "HISTOGRAM_CDF",
    "gaussian cdf": "GAUSSIAN_CDF",
    "cdf reconstruction": "CDF_RECONSTRUCTION",
    "chebyshev": "CHEBYSHEV",
    "exact box": "EXACT_BOX",
    "exact sphere": "EXACT_SPHERE",
}


def _readable(array):
    """The array as VTK can read it: C order, native byte order, a type VTK has."""
    values = np.ascontiguousarray(array)
    kind = values.dtype.kind
    if kind == "c":
        raise ValueError("complex values have no order to rank: pass the real part or the magnitude")
    if kind not in "biuf":
        raise ValueError("expected a numeric array, got dtype %s" % values.dtype)
    if kind == "b":
        return values.view(np.uint8)
    if values.dtype == np.float16:
        return values.astype(np.float32)
    # VTK reads the bytes in the machine's order: another order would be silently wrong.
    return values.astype(values.dtype.newbyteorder("="), copy=False)


def _image(array, spacing, origin):
    values = _readable(array)
    if values.ndim != 3:
        raise ValueError("expected a 3-D array indexed [z, y, x], got shape %s" % (values.shape,))
    image = vtkImageData()
    image.SetDimensions(values.shape[2], values.shape[1], values.shape[0])
    image.SetSpacing(*[float(s) for s in spacing])
    image.SetOrigin(*[float(o) for o in origin])
    scalars = numpy_to_vtk(values.reshape(-1), deep=0)
    scalars.SetName("Scalars")
    image.GetPointData().SetScalars(scalars)
    return image, values  # keep `values` alive while VTK reads it


def _run(algorithm, shape, names):
    """Updates the algorithm; its errors become a RuntimeError; returns the named arrays."""
    errors = []

    @calldata_type(VTK_STRING)
    def on_error(caller, event, message):
        errors.append(str(message).strip())

    tag = algorithm.AddObserver(vtkCommand.ErrorEvent, on_error)
    algorithm.Update()
    algorithm.RemoveObserver(tag)
    output = algorithm.GetOutputDataObject(0)
    arrays = [output.GetPointData().GetArray(name) for name in names]
    if errors or any(a is None for a in arrays):
        raise RuntimeError("%s failed: %s" % (algorithm.GetClassName(), " ".join(errors) or "no output"))
    return [vtk_to_numpy(a).reshape(shape).copy() for a in arrays]


def ambient_occlusion(array, spacing=(1.0, 1.0, 1.0), radius=10.0, method="Histogram CDF", world_radius=False,
                      iso_value=None, query_smoothing=None, number_of_bins=64, variance=False, threads=0,
                      origin=(0.0, 0.0, 0.0)):
    """Per-voxel ambient occlusion (openness in [0, 1], 1 = open) of a volume.

    array: 3-D numpy array indexed [z, y, x], any numeric dtype, no NaN or infinity.
    spacing: voxel size (x, y, z); matters only with world_radius.
    radius: half-width of the box, in voxels (or in world units with world_radius=True).
    method: "Histogram CDF" (default, nearly exact), "Gaussian CDF", "CDF Reconstruction",
        "Chebyshev", "Exact Box", "Exact Sphere".
    iso_value: compare with this value instead of each voxel's own.
    query_smoothing: compare with the voxel's value smoothed by a Gaussian of this sigma
        (voxels) instead (ignored with iso_value).
    number_of_bins: Histogram CDF's thresholds (2..1024).
    variance: also return the box's intensity variance.
    threads: CPU threads (0: the default).
    Returns a float32 array of the input's shape, or (openness, variance) with variance=True.
    Raises ValueError, or RuntimeError with the filter's error message, on bad input.
    """
    from .VolumetricAOFilters import vtkVolumetricAmbientOcclusion

    key = _METHODS.get(str(method).lower())
    if key is None:
        raise ValueError("unknown method %r (one of %s)" % (method, ", ".join(sorted(_METHODS))))
    image, values = _image(array, spacing, origin)
    ao = vtkVolumetricAmbientOcclusion()
    ao.SetInputData(image)
    ao.SetMethod(getattr(vtkVolumetricAmbientOcclusion, key))
    ao.SetRadius(float(radius))
    ao.SetRadiusUnits(vtkVolumetricAmbientOcclusion.WORLD if world_radius else vtkVolumetricAmbientOcclusion.VOXELS)
    ao.SetNumberOfBins(int(number_of_bins))
    ao.SetNumberOfThreads(int(threads))
    ao.SetComputeVariance(bool(variance))
    ao.SetBackend(vtkVolumetricAmbientOcclusion.BACKEND_CPU)
    if iso_value is not None:
        ao.SetQueryMode(vtkVolumetricAmbientOcclusion.ISO_VALUE)
        ao.SetIsoValue(float(iso_value))
    elif query_smoothing is not None:
        ao.SetQueryMode(vtkVolumetricAmbientOcclusion.SMOOTHED_VALUE)
        ao.SetQuerySmoothing(float(query_smoothing))
    results = _run(ao, values.shape, ["AmbientOcclusion"] + (["Variance"] if variance else []))
    return tuple(results) if variance else results[0]


def occlusion_sweeping(array, iso_value, spacing=(1.0, 1.0, 1.0), inside_is_above=True, iterations=1,
                       threads=0, origin=(0.0, 0.0, 0.0)):
    """Occlusion sweeping (Singh et al. 2009) of the isosurface at iso_value.

    Returns (ambient_occlusion, signed_distance), float32 arrays of the input's shape:
    the skylight visibility of every voxel, and the signed distance to the surface (world
    units, negative inside).
    """
    from .VolumetricAOFilters import vtkOcclusionSweeping

    image, values = _image(array, spacing, origin)
    sweep = vtkOcclusionSweeping()
    sweep.SetInputData(image)
    sweep.SetIsoValue(float(iso_value))
    sweep.SetInsideIsAbove(bool(inside_is_above))
    sweep.SetNumberOfIterations(int(iterations))
    sweep.SetNumberOfThreads(int(threads))
    ao, distance = _run(sweep, values.shape, ["AmbientOcclusion", "SignedDistance"])
    return ao, distance
