"""numpy functions of the volume filters: Volumetric Ambient Occlusion, Occlusion
Sweeping and the Variance Occlusion Map.

Volumes are numpy arrays indexed ``[z, y, x]`` (C order) with ``sampling`` per array axis
as scipy.ndimage takes it, or vtkImageData (their spacing, origin and direction kept).
"""
import collections
import warnings

from . import _common
from .VolumetricAOFilters import vtkOcclusionSweeping, vtkVarianceOcclusionMap, vtkVolumetricAmbientOcclusion

_METHODS = {
    "histogram cdf": vtkVolumetricAmbientOcclusion.HISTOGRAM_CDF,
    "gaussian cdf": vtkVolumetricAmbientOcclusion.GAUSSIAN_CDF,
    "cdf reconstruction": vtkVolumetricAmbientOcclusion.CDF_RECONSTRUCTION,
    "chebyshev": vtkVolumetricAmbientOcclusion.CHEBYSHEV,
    "exact box": vtkVolumetricAmbientOcclusion.EXACT_BOX,
    "exact sphere": vtkVolumetricAmbientOcclusion.EXACT_SPHERE,
    "transfer function": vtkVolumetricAmbientOcclusion.TRANSFER_FUNCTION,
    "exact rays": vtkVolumetricAmbientOcclusion.EXACT_RAYS,
    "rays": vtkVolumetricAmbientOcclusion.RAYS,
}
# The methods that read an opacity function.
_OPACITY_METHODS = {vtkVolumetricAmbientOcclusion.TRANSFER_FUNCTION: "transfer function",
                    vtkVolumetricAmbientOcclusion.EXACT_RAYS: "exact rays",
                    vtkVolumetricAmbientOcclusion.RAYS: "rays"}
_ERF = {"exact": vtkVolumetricAmbientOcclusion.ERF_EXACT, "winitzki": vtkVolumetricAmbientOcclusion.ERF_WINITZKI}
_BACKEND = {"auto": vtkVolumetricAmbientOcclusion.BACKEND_AUTO, "cpu": vtkVolumetricAmbientOcclusion.BACKEND_CPU,
            "cuda": vtkVolumetricAmbientOcclusion.BACKEND_CUDA}

Level = collections.namedtuple("Level", ["mean", "variance", "sampling", "origin"])
Level.__doc__ = """One level of the variance occlusion map: the float32 arrays ``mean`` and
``variance`` indexed [z, y, x], the level's ``sampling`` and the position of its first voxel
``origin``, both in array order (z, y, x)."""


def _volume(array, sampling, spacing, origin):
    """The input as an image (_common.volume_image), with the deprecated origin (x, y, z)
    of a numpy array applied; a vtkImageData carries its own."""
    volume = _common.volume_image(array, sampling, spacing)
    if origin is None:
        return volume
    if volume.keep is None:
        raise TypeError("a vtkImageData carries its own origin: leave origin out")
    warnings.warn("origin (x, y, z) is deprecated and will be removed after 0.3: it does not change the results",
                  DeprecationWarning, stacklevel=3)
    volume.image.SetOrigin(*_common.three(origin, "origin"))
    return volume


def ambient_occlusion(array, spacing=None, radius=10.0, method="Histogram CDF", world_radius=False,
                      iso_value=None, query_smoothing=None, number_of_bins=64, variance=False, threads=0,
                      origin=None, *, sampling=None, component=None, scalars=None, erf="exact", backend="auto",
                      device=-1, opacity=None, ray_count=128, opacity_unit_distance=None, progress=False,
                      return_info=False):
    """Per-voxel ambient occlusion (openness in [0, 1], 1 = open) of a volume: the
    Volumetric Ambient Occlusion filter (``vtkVolumetricAmbientOcclusion``).

    array: a numpy array indexed [z, y, x] (any numeric dtype, no NaN or infinity; 4-D
        [z, y, x, c] with ``component``), or a vtkImageData (or an algorithm whose output
        is one; then ``scalars`` names its point array, default the active scalars).
    sampling: the voxel size per array axis (z, y, x), or one value for all (default 1);
        it matters with ``world_radius`` and for the rays. ``spacing`` (x, y, z) is its deprecated form.
    radius: half-width of the box, in voxels (in the units of ``sampling`` with
        ``world_radius=True``).
    method: "Histogram CDF" (default, nearly exact), "Gaussian CDF", "CDF Reconstruction",
        "Chebyshev", "Exact Box", "Exact Sphere" (case and underscores do not matter),
        "Transfer Function": 1 - the box's mean opacity, with ``opacity``, or "Exact Rays":
        the ambient occlusion a ray tracer shows through ``opacity``, the mean transmittance
        of ``ray_count`` rays of length ``radius`` (in voxels: times the smallest sampling), or
        "Rays": the same AO estimated at a cost that grows like log(radius).
    opacity: the opacity transfer function of methods "transfer function", "exact rays" and "rays": a
        vtkPiecewiseFunction, ParaView's ``GetOpacityTransferFunction(array)``, or points
        ((N, 2) value and opacity, (N, 4) with midpoint and sharpness, as VTK takes them).
    iso_value: compare with this value instead of each voxel's own.
    query_smoothing: compare with the voxel's value smoothed by a Gaussian of this sigma
        (voxels) instead (ignored with iso_value).
    number_of_bins: Histogram CDF's thresholds (2..1024).
    variance: also return the box's intensity variance.
    erf: "exact" or "winitzki" (Gaussian CDF's error function).
    ray_count: "exact rays": the rays per voxel (1..65536), spread over a Fibonacci sphere.
    opacity_unit_distance: "exact rays" and "rays": the length (units of ``sampling``) over which a
        voxel stops the fraction of light ``opacity`` gives; default the smallest sampling.
    backend: "auto" (CUDA for large extents and the exact methods when a device is present),
        "cpu" or "cuda" (falls back to the CPU with a VolumetricAOWarning); device: the
        CUDA device (-1: the process's rank on its node modulo the devices).
    threads: CPU threads (0: the cores this process may use).
    progress: True for a progress bar (tqdm if installed, else stderr), or a callable
        taking the fraction done.
    return_info: also return a RunInfo (backend, device, threads) of what ran.

    Returns a float32 array of the volume's shape, or (openness, variance) with
    variance=True; with return_info, (that, info).

    >>> import numpy as np, volumetricao
    >>> volume = np.random.default_rng(0).normal(size=(20, 30, 40)).astype(np.float32)
    >>> ao = volumetricao.ambient_occlusion(volume, radius=3)
    >>> ao.shape, ao.dtype, bool(((ao >= 0) & (ao <= 1)).all())
    ((20, 30, 40), dtype('float32'), True)
    >>> ao, var = volumetricao.ambient_occlusion(volume, radius=4.0, world_radius=True,
    ...                                          sampling=(2.0, 1.0, 1.0), variance=True)
    >>> ao, info = volumetricao.ambient_occlusion(volume, radius=3, backend="cpu", threads=2,
    ...                                           return_info=True)
    >>> info
    RunInfo(backend='CPU', device='CPU', threads=2)
    >>> volumetricao.ambient_occlusion(volume, radius=0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: Radius 0 rounds to 0 voxels on every axis: ... Use at least one voxel.

    The openness of what a volume rendering shows, with bone (above 0.7) transparent:

    >>> shown = volumetricao.ambient_occlusion(volume, radius=3, method="transfer function",
    ...                                        opacity=[(-1, 0), (0, 0.8), (0.7, 0.8), (0.71, 0)])
    >>> bool(((shown >= 0) & (shown <= 1)).all())
    True
    """
    chosen = _common.choice(method, _METHODS, "method")
    if chosen in _OPACITY_METHODS and opacity is None:
        raise ValueError('method="%s" needs opacity: points (value, opacity) or a vtkPiecewiseFunction'
                         % _OPACITY_METHODS[chosen])
    if chosen not in _OPACITY_METHODS and opacity is not None:
        raise ValueError('opacity is used by methods "transfer function", "exact rays" and "rays" only')
    if chosen != vtkVolumetricAmbientOcclusion.EXACT_RAYS and ray_count != 128:
        raise ValueError('ray_count is used by method="exact rays" only')
    rays = chosen in (vtkVolumetricAmbientOcclusion.EXACT_RAYS, vtkVolumetricAmbientOcclusion.RAYS)
    if not rays and opacity_unit_distance is not None:
        raise ValueError('opacity_unit_distance is used by methods "exact rays" and "rays" only')
    function = None if opacity is None else _common.opacity_function(opacity)
    erf_key = _common.choice(erf, _ERF, "erf")
    backend_key = _common.check_backend(backend)
    volume = _volume(array, sampling, spacing, origin)
    _common.check_volume(volume, component, "array")
    ao = vtkVolumetricAmbientOcclusion()
    ao.SetController(None)  # this process's array is the whole volume
    ao.SetInputData(volume.image)
    _common.choose_scalars(ao, scalars)
    _common.set_component(ao, component)
    ao.SetMethod(chosen)
    if function is not None:
        ao.SetOpacityFunction(function)
    ao.SetRadius(_common.number(radius, "radius"))
    ao.SetRadiusUnits(vtkVolumetricAmbientOcclusion.WORLD if world_radius else vtkVolumetricAmbientOcclusion.VOXELS)
    ao.SetNumberOfBins(_common.number(number_of_bins, "number_of_bins", integer=True))
    ao.SetRayCount(_common.number(ray_count, "ray_count", integer=True))
    if opacity_unit_distance is not None:
        ao.SetOpacityUnitDistance(_common.number(opacity_unit_distance, "opacity_unit_distance"))
    ao.SetNumberOfThreads(_common.check_threads(threads))
    ao.SetComputeVariance(bool(variance))
    ao.SetErfApproximation(erf_key)
    ao.SetBackend(_BACKEND[backend_key])
    ao.SetDevice(_common.number(device, "device", integer=True))
    if iso_value is not None:
        ao.SetQueryMode(vtkVolumetricAmbientOcclusion.ISO_VALUE)
        ao.SetIsoValue(_common.number(iso_value, "iso_value"))
    elif query_smoothing is not None:
        ao.SetQueryMode(vtkVolumetricAmbientOcclusion.SMOOTHED_VALUE)
        ao.SetQuerySmoothing(_common.number(query_smoothing, "query_smoothing"))
    output = _common.run(ao, progress, label="ambient_occlusion", image=volume.image)
    names = ["AmbientOcclusion"] + (["Variance"] if variance else [])
    results = _common.point_arrays(output, names, volume.shape, "vtkVolumetricAmbientOcclusion")
    return _common.finish(tuple(results) if variance else results[0], output, return_info, reported=True)


def occlusion_sweeping(array, iso_value, spacing=None, inside_is_above=True, iterations=1, threads=0,
                       origin=None, *, sampling=None, tolerance=0.0, geometry_term=False, octant_mask=None,
                       gamma=1.0, opacity=1.0, octant_visibility=False, component=None, scalars=None,
                       backend="auto", progress=False, return_info=False):
    """Occlusion sweeping (Singh et al. 2009) of the isosurface at iso_value: the
    Occlusion Sweeping filter (``vtkOcclusionSweeping``). Global: an occluder anywhere
    shadows everything behind it.

    array, sampling, spacing, component, scalars: as for ambient_occlusion; ``sampling``
        sets the signed distance's units.
    inside_is_above: values above iso_value occlude (False: values below it).
    iterations: passes of the eight sweeps; tolerance > 0 stops them once the distance
        changes by less (units of ``sampling``).
    geometry_term: weight the octants by the cosine of the surface normal (off: their
        mean visibility, the paper's Fig. 6).
    octant_mask: 8 flags, the octants that shed light (default all), in the order of the
        paper's Table 1: sweep signs (x, y, z) = (1,1,1), (-1,1,1), (1,-1,1), (-1,-1,1),
        (1,1,-1), (-1,1,-1), (1,-1,-1), (-1,-1,-1), where x is the array's last axis and z
        its first; ``[0, 0, 0, 0, 1, 1, 1, 1]``: light from +z (the high end of axis 0).
    gamma: AO <- AO^(1/gamma). opacity: of the occluders, in [0, 1].
    octant_visibility: also return each octant's visibility, [z, y, x, 8].
    backend: "auto" or "cpu" (the filter has no GPU path; "cuda" warns and runs on the CPU).
    threads, progress, return_info: as for ambient_occlusion.

    Returns (ambient_occlusion, signed_distance), float32 arrays of the volume's shape
    (the distance in the units of ``sampling``, negative inside), and the octant
    visibility third with octant_visibility=True.

    >>> import numpy as np, volumetricao
    >>> z, y, x = np.mgrid[:24, :24, :24]
    >>> ball = ((z - 12) ** 2 + (y - 12) ** 2 + (x - 12) ** 2 < 36).astype(np.uint8)
    >>> sky, distance = volumetricao.occlusion_sweeping(ball, iso_value=0.5, sampling=0.5)
    >>> float(sky[12, 12, 12]), bool(distance[12, 12, 12] < 0 < distance[0, 0, 0])
    (0.0, True)
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     sky, distance = volumetricao.occlusion_sweeping(ball, iso_value=5.0)
    >>> print(caught[0].category.__name__, caught[0].message)  # doctest: +ELLIPSIS
    VolumetricAOWarning IsoValue 5 does not cross array 'Scalars': there is no surface; ...
    """
    backend_key = _common.check_backend(backend)
    volume = _volume(array, sampling, spacing, origin)
    _common.check_volume(volume, component, "array")
    sweep = vtkOcclusionSweeping()
    sweep.SetController(None)
    sweep.SetInputData(volume.image)
    _common.choose_scalars(sweep, scalars)
    _common.set_component(sweep, component)
    sweep.SetIsoValue(_common.number(iso_value, "iso_value"))
    sweep.SetInsideIsAbove(bool(inside_is_above))
    sweep.SetNumberOfIterations(_common.number(iterations, "iterations", integer=True))
    sweep.SetConvergenceTolerance(_common.number(tolerance, "tolerance"))
    sweep.SetUseGeometryTerm(bool(geometry_term))
    if octant_mask is not None:
        sweep.SetOctantMask(*_common.flags(octant_mask, "octant_mask (Table 1 order)", 8))
    sweep.SetGamma(_common.number(gamma, "gamma"))
    sweep.SetOpacity(_common.number(opacity, "opacity"))
    sweep.SetOutputOctantVisibility(bool(octant_visibility))
    sweep.SetNumberOfThreads(_common.check_threads(threads))
    output = _common.run(sweep, progress, cuda_asked=backend_key == "cuda", label="occlusion_sweeping",
                         image=volume.image)
    names = ["AmbientOcclusion", "SignedDistance"] + (["OctantVisibility"] if octant_visibility else [])
    results = _common.point_arrays(output, names, volume.shape, "vtkOcclusionSweeping")
    return _common.finish(tuple(results), output, return_info)


def variance_occlusion_map(volume, *, sampling=None, levels=4, start_at_half_resolution=False, component=None,
                           scalars=None, threads=0, backend="auto", progress=False, return_info=False):
    """The variance occlusion maps (Penner & Mitchell 2008): the pyramid of blurred local
    means and variances the isosurface AO samples (``vtkVarianceOcclusionMap``).

    volume, sampling, component, scalars: as for ambient_occlusion.
    levels: pyramid levels (1..16); level l keeps every 2^l-th voxel (2^(l+1)-th with
        start_at_half_resolution) counted from the first.
    backend: "auto" or "cpu" ("cuda" warns and runs on the CPU); threads, progress,
        return_info: as for ambient_occlusion.

    Returns a list of Level(mean, variance, sampling, origin), finest first: float32
    arrays indexed [z, y, x], and the level's sampling and first voxel's position in array
    order (z, y, x), in the volume's units (a numpy volume starts at 0).

    >>> import numpy as np, volumetricao
    >>> volume = np.random.default_rng(1).random((32, 24, 16), dtype=np.float32)
    >>> maps = volumetricao.variance_occlusion_map(volume, levels=3, sampling=(2.0, 1.0, 1.0))
    >>> [(level.mean.shape, level.sampling) for level in maps]
    [((32, 24, 16), (2.0, 1.0, 1.0)), ((16, 12, 8), (4.0, 2.0, 2.0)), ((8, 6, 4), (8.0, 4.0, 4.0))]
    """
    backend_key = _common.check_backend(backend)
    given = _common.volume_image(volume, sampling)
    _common.check_volume(given, component, "volume")
    pyramid = vtkVarianceOcclusionMap()
    pyramid.SetInputData(given.image)
    _common.choose_scalars(pyramid, scalars)
    _common.set_component(pyramid, component)
    pyramid.SetNumberOfLevels(_common.number(levels, "levels", integer=True))
    pyramid.SetStartAtHalfResolution(bool(start_at_half_resolution))
    pyramid.SetNumberOfThreads(_common.check_threads(threads))
    output = _common.run(pyramid, progress, cuda_asked=backend_key == "cuda", label="variance_occlusion_map",
                         image=given.image)
    result = []
    for index in range(output.GetNumberOfBlocks()):
        level = output.GetBlock(index)
        nx, ny, nz = level.GetDimensions()
        mean, var = _common.point_arrays(level, ["Mean", "Variance"], (nz, ny, nx), "vtkVarianceOcclusionMap")
        result.append(Level(mean, var, tuple(reversed(level.GetSpacing())), tuple(reversed(level.GetOrigin()))))
    return _common.finish(result, output, return_info)
