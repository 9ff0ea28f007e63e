"""numpy functions of the surface and colour filters: Isosurface Ambient Occlusion (AO
and soft shadows of a mesh's vertices) and Ambient Occlusion Shading (colours).

Vertices, normals and directions are in array order (z, y, x), like the vertices of
``skimage.measure.marching_cubes(volume, level, spacing=sampling)``: index times sampling.
"""
import math

import numpy as np

from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData

from . import _common
from .VolumetricAOFilters import vtkAmbientOcclusionShading, vtkIsosurfaceAmbientOcclusion

_COMBINE = {"max": vtkIsosurfaceAmbientOcclusion.COMBINE_MAX, "mean": vtkIsosurfaceAmbientOcclusion.COMBINE_MEAN}
_ESTIMATOR = {"chebyshev": vtkIsosurfaceAmbientOcclusion.CHEBYSHEV,
              "gaussian cdf": vtkIsosurfaceAmbientOcclusion.GAUSSIAN_CDF}
_PRESETS = {"grayscale": vtkAmbientOcclusionShading.GRAYSCALE, "bone": vtkAmbientOcclusionShading.BONE,
            "cool to warm": vtkAmbientOcclusionShading.COOL_TO_WARM}


def _xyz(values, name, count=None):
    """An (N, 3) array in (z, y, x) order as a contiguous (N, 3) array in VTK's (x, y, z)
    order; float32 stays float32, anything else becomes float64."""
    array = np.asarray(values)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError("%s: expected an (N, 3) array in (z, y, x) order, got shape %s" % (name, array.shape))
    if count is not None and array.shape[0] != count:
        raise ValueError("%s: one row per vertex (%d), got %d" % (name, count, array.shape[0]))
    if array.dtype.kind not in "iuf":
        raise ValueError("%s: expected numbers, got dtype %s" % (name, array.dtype))
    dtype = np.float32 if array.dtype == np.float32 else np.float64
    return np.ascontiguousarray(array[:, ::-1], dtype=dtype)


def _per_vertex(values, name, count):
    array = _common.readable(values, name)
    if array.shape != (count,):
        raise ValueError("%s: one value per vertex (%d,), got shape %s" % (name, count, array.shape))
    return array


def _check_vertices(points_xyz, image):
    """What the filter refuses of the vertices on a numpy volume, said in numpy's terms
    before it runs: a vertex that is not finite, or one outside the volume by more than
    half a voxel (the filter's test, on the same doubles: it names VTK's axis)."""
    zyx = points_xyz[:, ::-1].astype(np.float64)  # exact, and compared as the filter compares
    bad = ~np.isfinite(zyx).all(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        raise ValueError("vertices: vertex %d (row %d) is not finite (%s): remove it, e.g. "
                         "vertices[np.isfinite(vertices).all(axis=1)]" % (row, row, ", ".join(map(repr, zyx[row]))))
    h = np.array(image.GetSpacing()[::-1])
    shape = np.array(image.GetDimensions()[::-1])
    top = 0.0 + (shape - 1) * h                   # the last voxel; the first is at 0
    outside = (zyx < 0.0 - 0.5 * h) | (zyx > top + 0.5 * h)
    rows = outside.any(axis=1)
    if rows.any():
        row = int(np.argmax(rows))
        axis = int(np.argmax(outside[row]))
        raise ValueError(
            "The surface reaches outside the volume: vertex %d (row %d of vertices) lies at %g along axis %d, beyond "
            "the volume's 0..%g along that axis by more than half a voxel (shape %s, sampling %s); %d of the %d "
            "vertices lie outside. Give the volume the vertices were extracted from, with its sampling: vertices "
            "are (z, y, x) positions in the units of sampling, counted from the first voxel."
            % (row, row, zyx[row, axis], axis, top[axis], tuple(int(n) for n in shape),
               tuple(float(v) for v in h), int(rows.sum()), len(rows)))


def _check_light(light):
    """The filter's test of the light direction (x, y, z), said in numpy's (z, y, x)."""
    x, y, z = light[2], light[1], light[0]
    length = math.sqrt(x * x + y * y + z * z)
    if not (math.isfinite(length) and length > 0.0):
        raise ValueError("light_direction must be a finite, non-zero direction towards the light in (z, y, x) order, "
                         "got %s" % (light,))


def isosurface_ambient_occlusion(volume, vertices, normals=None, *, sampling=None, iso_value=None, levels=4,
                                 start_at_half_resolution=False, offset_factor=1.0, combine="max",
                                 estimator="chebyshev", shadows=False, light_direction=(1.0, 0.0, 0.0),
                                 component=None, scalars=None, threads=0, backend="auto", progress=False,
                                 return_info=False):
    """Ambient occlusion and soft shadows of an isosurface's vertices (Penner & Mitchell
    2008): the Isosurface Ambient Occlusion filter (``vtkIsosurfaceAmbientOcclusion``).

    volume: the volume the surface comes from: a numpy array [z, y, x] with ``sampling``
        per axis (as for ambient_occlusion), or a vtkImageData (``scalars`` names its array).
    vertices: (N, 3) positions in array order (z, y, x), in the units of ``sampling`` and
        counted from the first voxel: what ``skimage.measure.marching_cubes(volume, level,
        spacing=sampling)`` returns as ``verts``. For a vtkImageData volume, its world
        coordinates (origin included) in (z, y, x) order.
    normals: (N, 3) in (z, y, x) order, pointing out of the occluding material (towards
        lower values); None: the volume's gradient, oriented so.
    iso_value: compare the samples with this value (None: with the volume half a voxel
        inside the surface, the paper's choice).
    levels, start_at_half_resolution: the pyramid (see variance_occlusion_map).
    offset_factor: level l is sampled offset_factor x its radius outside the surface.
    combine: "max" (the largest occlusion of the levels) or "mean".
    estimator: "chebyshev" (the paper's bound) or "gaussian cdf".
    shadows: also return soft shadows (1 = lit) towards ``light_direction``, a direction
        towards the light in (z, y, x) order (default (1, 0, 0): from the high end of
        axis 0, VTK's +z).
    backend: "auto" or "cpu" ("cuda" warns and runs on the CPU); threads, progress,
        return_info: as for ambient_occlusion.

    Returns the float32 AO per vertex (1 = open), or (ao, shadow) with shadows=True.

    >>> import numpy as np, volumetricao
    >>> z, y, x = np.mgrid[:40, :40, :40].astype(float)
    >>> blob = 100 * np.exp(-((z - 20) ** 2 + (y - 20) ** 2 + (x - 20) ** 2) / 72)   # iso 50: r = 7.06
    >>> floor = 100 * np.exp(-(z - 7) ** 2 / 4 - ((y - 20) ** 2 + (x - 20) ** 2) / 200)
    >>> r = 6 * np.sqrt(2 * np.log(2))
    >>> vertices = np.array([[20 + r, 20, 20], [20 - r, 20, 20]])      # the blob's top, its bottom
    >>> ao, shadow = volumetricao.isosurface_ambient_occlusion(blob + floor, vertices, shadows=True)
    >>> ao.dtype, bool(ao[1] < 0.5 < ao[0]), bool(shadow[1] < 0.5 < shadow[0])
    (dtype('float32'), True, True)
    """
    backend_key = _common.check_backend(backend)
    given = _common.volume_image(volume, sampling)
    _common.check_volume(given, component, "volume")
    image = given.image
    points_xyz = _xyz(vertices, "vertices")
    if given.keep is not None:
        _check_vertices(points_xyz, image)  # a vtkImageData's own frame: the filter's message, translated
    count = points_xyz.shape[0]
    surface = vtkPolyData()
    points = vtkPoints()
    points.SetData(_common.vtk_array(points_xyz, "Points"))
    surface.SetPoints(points)
    if normals is not None:
        normals_xyz = _xyz(normals, "normals", count)
        surface.GetPointData().SetNormals(_common.vtk_array(normals_xyz, "Normals"))
    light = _common.three(light_direction, "light_direction")
    if shadows:
        _check_light(light)
    iso = vtkIsosurfaceAmbientOcclusion()
    iso.SetController(None)
    iso.SetInputData(surface)
    iso.SetVolumeData(image)
    if scalars is not None:
        iso.SetVolumeScalars(str(scalars))
    _common.set_component(iso, component)
    if iso_value is not None:
        iso.SetQueryMode(vtkIsosurfaceAmbientOcclusion.ISO_VALUE)
        iso.SetIsoValue(_common.number(iso_value, "iso_value"))
    iso.SetNumberOfLevels(_common.number(levels, "levels", integer=True))
    iso.SetStartAtHalfResolution(bool(start_at_half_resolution))
    iso.SetOffsetFactor(_common.number(offset_factor, "offset_factor"))
    iso.SetCombine(_common.choice(combine, _COMBINE, "combine"))
    iso.SetEstimator(_common.choice(estimator, _ESTIMATOR, "estimator"))
    iso.SetComputeShadows(bool(shadows))
    iso.SetLightDirection(light[2], light[1], light[0])
    iso.SetNumberOfThreads(_common.check_threads(threads))
    output = _common.run(iso, progress, cuda_asked=backend_key == "cuda", label="isosurface_ambient_occlusion",
                         image=image, vertices=True)
    names = ["AmbientOcclusion"] + (["Shadow"] if shadows else [])
    results = _common.point_arrays(output, names, (count,), "vtkIsosurfaceAmbientOcclusion")
    return _common.finish(tuple(results) if shadows else results[0], output, return_info)


def shade(values, ao=None, *, variance=None, shadow=None, sampling=None, color_preset="grayscale",
          scalar_range=None, opacity_ramp=None, ambient_intensity=1.0, gamma=1.0, variance_max=0.0,
          color_transfer_function=None, opacity_transfer_function=None, scalars=None, threads=0, backend="auto",
          progress=False, return_info=False):
    """Colours by ambient occlusion (Ruiz et al. 2010, Eq. 5): the Ambient Occlusion
    Shading filter (``vtkAmbientOcclusionShading``).

    A volume: ``values`` a numpy array [z, y, x] (or a vtkImageData; ``scalars`` names its
    array) and ``ao`` its openness (the same shape; for a vtkImageData None takes its
    "AmbientOcclusion" array). Returns uint8 RGBA [z, y, x, 4]: RGB = ambient_intensity x
    AO^(1/gamma) x colour(value), A = the opacity ramp at the value, times
    min(variance / variance_max, 1) when ``variance`` is given (for a vtkImageData
    ``variance=True`` takes its "Variance" array).

    A surface: ``values`` None (white) or one value per vertex (N,), ``ao`` (N,) and
    optionally ``shadow`` (N,). Returns uint8 RGB (N, 3): colour(value) x (AO x
    shadow)^(1/gamma) x ambient_intensity.

    color_preset: "grayscale", "bone" or "cool to warm", spread over ``scalar_range``
        (default the values' range). opacity_ramp: (low, high), the opacity rising from 0
        to 1 (default the upper half of the range). variance_max <= 0: (range / 20)^2.
    color_transfer_function, opacity_transfer_function: a vtkScalarsToColors and a
        vtkPiecewiseFunction (or opacity points, as ambient_occlusion's ``opacity`` takes
        them) instead of the preset and the ramp.
    backend: "auto" or "cpu" ("cuda" warns and runs on the CPU); threads, progress,
        return_info: as for ambient_occlusion.

    >>> import numpy as np, volumetricao
    >>> volume = np.random.default_rng(2).normal(size=(16, 16, 16)).astype(np.float32)
    >>> ao = volumetricao.ambient_occlusion(volume, radius=2)
    >>> rgba = volumetricao.shade(volume, ao, color_preset="bone")
    >>> rgba.shape, rgba.dtype
    ((16, 16, 16, 4), dtype('uint8'))
    >>> volumetricao.shade(None, np.array([1.0, 0.5, 0.0]))
    array([[255, 255, 255],
           [128, 128, 128],
           [  0,   0,   0]], dtype=uint8)
    """
    backend_key = _common.check_backend(backend)
    image = _common.image_data(values) if values is not None else None
    keep = []
    if image is not None or (values is not None and np.ndim(values) >= 3):
        volume = _common.volume_image(values, sampling)
        data, shape, output_name = volume.image, volume.shape, "ShadedRGBA"
        keep.append(volume.keep)
        if ao is None and volume.keep is not None:
            raise TypeError("shade(volume, ao): give the ambient occlusion of the volume")
        if volume.keep is not None:
            _common.check_finite(volume.keep, "values", _common.IN_COLOURS)
    else:
        if ao is None:
            raise TypeError("shade(values, ao): give the ambient occlusion of the vertices")
        count = int(np.size(ao))
        data, shape, output_name = vtkPolyData(), (count,), "ShadedRGB"
        origin = np.zeros((count, 3), np.float32)  # where the points are does not change their colour
        keep.append(origin)
        points = vtkPoints()
        points.SetData(_common.vtk_array(origin, "Points"))
        data.SetPoints(points)
        if values is not None:
            scalars_values = _per_vertex(values, "values", count)
            _common.check_finite(scalars_values, "values", _common.IN_COLOURS)
            keep.append(scalars_values)
            data.GetPointData().SetScalars(_common.vtk_array(scalars_values, "Scalars"))
    point_data = data.GetPointData()

    surface = output_name == "ShadedRGB"

    def add(array, name, argument, read):
        if isinstance(array, bool) or array is None:
            return
        given = _common.readable(array, name)
        if given.shape != tuple(shape):
            raise ValueError("%s: expected the shape of the values %s, got %s" % (name, tuple(shape), given.shape))
        if read:  # the filter refuses NaN in the arrays it reads; it names them by VTK's point id
            _common.check_finite(given, argument, _common.IN_COLOURS)
        keep.append(given)
        point_data.AddArray(_common.vtk_array(given, name))

    add(ao, "AmbientOcclusion", "ao", True)
    add(variance, "Variance", "variance", not surface)
    add(shadow, "Shadow", "shadow", surface)
    shading = vtkAmbientOcclusionShading()
    shading.SetController(None)
    shading.SetInputData(data)
    if scalars is not None:
        shading.SetScalarsArrayName(str(scalars))
    shading.SetColorPreset(_common.choice(color_preset, _PRESETS, "color_preset"))
    if scalar_range is not None:
        shading.SetScalarRange(*_common.pair(scalar_range, "scalar_range"))
    if opacity_ramp is not None:
        shading.SetOpacityRamp(*_common.pair(opacity_ramp, "opacity_ramp"))
    shading.SetAmbientIntensity(_common.number(ambient_intensity, "ambient_intensity"))
    shading.SetGamma(_common.number(gamma, "gamma"))
    shading.SetModulateOpacity(variance is not None and variance is not False)
    shading.SetVarianceMax(_common.number(variance_max, "variance_max"))
    if color_transfer_function is not None:
        shading.SetColorTransferFunction(color_transfer_function)
    if opacity_transfer_function is not None:
        shading.SetOpacityTransferFunction(
            _common.opacity_function(opacity_transfer_function, "opacity_transfer_function"))
    shading.SetNumberOfThreads(_common.check_threads(threads))
    output = _common.run(shading, progress, cuda_asked=backend_key == "cuda", label="shade",
                         image=None if surface else data, vertices=surface)
    (colours,) = _common.point_arrays(output, [output_name], shape, "vtkAmbientOcclusionShading")
    return _common.finish(colours, output, return_info)
