"""pvpython: load the plugin, check the proxy's properties, run every method on Wavelet
and on the CT head phantom, check arrays and ranges, write the result and read it back.

Usage: pvpython test_plugin.py PLUGIN DATA_DIR OUTPUT_DIR"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vao_test_utils import METHODS, array_of, check, finish, read_image  # noqa: E402

from paraview.simple import *  # noqa: E402,F401,F403
from paraview import servermanager  # noqa: E402
import numpy as np  # noqa: E402

plugin, data_dir, out_dir = sys.argv[1:4]
LoadPlugin(plugin, ns=globals())
check("VolumetricAmbientOcclusion" in globals(), "the plugin defines VolumetricAmbientOcclusion", stop=True)

# One version everywhere a user looks: the plugin (Manage Plugins), the CMake package,
# CITATION.cff and the newest CHANGELOG entry.
import re  # noqa: E402
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
plugins = servermanager.vtkPVPluginsInformation()
servermanager.ActiveConnection.Session.GatherInformation(servermanager.vtkPVSession.CLIENT, plugins, 0)
plugin_version = [plugins.GetPluginVersion(i) for i in range(plugins.GetNumberOfPlugins())
                  if plugins.GetPluginName(i) == "VolumetricAO"]
config = os.path.join(os.path.dirname(plugin), "..", "..", "..", "cmake", "VolumetricAO",
                      "VolumetricAOConfigVersion.cmake")
package_version = re.search(r'set\(PACKAGE_VERSION "([0-9.]+)"\)', open(config).read()).group(1)
citation_version = re.search(r"^version: *([0-9.]+)", open(os.path.join(root, "CITATION.cff")).read(), re.M).group(1)
changelog_version = re.search(r"^## ([0-9.]+)", open(os.path.join(root, "CHANGELOG.md")).read(), re.M).group(1)
check(plugin_version == [package_version] and package_version == citation_version == changelog_version,
      "one version: plugin %s, CMake package %s, CITATION.cff %s, CHANGELOG %s"
      % (plugin_version, package_version, citation_version, changelog_version))

wavelet = Wavelet(WholeExtent=[-12, 12, -10, 10, -8, 8])
ao = VolumetricAmbientOcclusion(Input=wavelet)

# Properties: names, defaults, enumeration texts, documentation.
expected_enums = {
    "Method": METHODS + ["Transfer Function", "Exact Rays", "Rays"],  # the last three need an opacity function
    "RadiusUnits": ["Voxels", "World"],
    "QueryMode": ["Voxel Value", "Iso Value", "Smoothed Voxel Value"],
    "ErfApproximation": ["Exact", "Winitzki"],
    "Backend": ["Auto", "CPU", "CUDA"],
}
for name, texts in expected_enums.items():
    check(list(ao.GetProperty(name).Available) == texts, "%s offers %s" % (name, texts))
check(ao.Method == "Histogram CDF", "Method defaults to Histogram CDF")
check(ao.NumberOfBins == 64 and ao.QuerySmoothing == 1.0, "NumberOfBins defaults to 64, QuerySmoothing to 1")
check(ao.Radius == 10, "Radius defaults to 10")
check(ao.QueryMode == "Smoothed Voxel Value", "QueryMode defaults to Smoothed Voxel Value in ParaView")
check(ao.OutputArrayName == "AmbientOcclusion", "OutputArrayName defaults to AmbientOcclusion")
for name in ["Scalars", "Method", "NumberOfBins", "Radius", "RadiusUnits", "QueryMode", "IsoValue",
             "QuerySmoothing", "ErfApproximation", "ComputeVariance", "Backend", "Device", "OutputArrayName",
             "Component", "NumberOfThreads", "RayCount", "OpacityUnitDistance"]:
    prop = ao.GetProperty(name)
    check(prop is not None, "property %s exists" % name, stop=True)
    doc = prop.SMProperty.GetDocumentation()
    check(doc is not None and len(doc.GetDescription().strip()) > 20, "property %s is documented" % name)


def run(source, array, method, radius, **extra):
    # The references compare with each voxel's own value unless a query is given (the
    # panel's default is the smoothed value).
    extra.setdefault("QueryMode", "Voxel Value")
    filt = VolumetricAmbientOcclusion(Input=source, Method=method, Radius=radius, ComputeVariance=1, **extra)
    filt.Scalars = ["POINTS", array]
    filt.UpdatePipeline()
    data = servermanager.Fetch(filt)
    Delete(filt)
    return data


def check_result(data, what, points):
    check(data.GetNumberOfPoints() == points, "%s: output has all %d points" % (what, points))
    ao_values = array_of(data, "AmbientOcclusion")
    variance = array_of(data, "Variance")
    check(data.GetPointData().GetArray("AmbientOcclusion").GetDataTypeAsString() == "float",
          "%s: AmbientOcclusion is float32" % what)
    check(ao_values.min() >= 0.0 and ao_values.max() <= 1.0, "%s: AO in [0, 1] (%.4f .. %.4f)"
          % (what, ao_values.min(), ao_values.max()))
    check(ao_values.max() - ao_values.min() > 0.2, "%s: AO is not constant" % what)
    check(variance.min() >= 0.0 and variance.max() > 0.0, "%s: variance >= 0 and not all 0" % what)
    return ao_values


wavelet_points = 25 * 21 * 17
results = {m: check_result(run(wavelet, "RTData", m, 3), "Wavelet/" + m, wavelet_points) for m in METHODS}
check(np.all(results["Chebyshev"] <= results["Exact Box"] + 1e-6), "Wavelet: Chebyshev <= Exact Box")

ct_path = os.path.join(data_dir, "ct_head_phantom", "ct_head_phantom_128x128x136_int16.mha")
ct = OpenDataFile(ct_path)
ct_points = 128 * 128 * 136
for method in METHODS:
    radius = 5 if method not in ("Exact Box", "Exact Sphere") else 3
    check_result(run(ct, "MetaImage", method, radius), "CT head/" + method, ct_points)

# Iso value query and world units.
iso = run(ct, "MetaImage", "Gaussian CDF", 10.0, RadiusUnits="World", QueryMode="Iso Value", IsoValue=400.0)
check_result(iso, "CT head/iso 400 world 10 mm", ct_points)
# The smoothed query with the exact count and with the default method.
for method in ("Exact Box", "Histogram CDF"):
    smoothed = run(ct, "MetaImage", method, 3, QueryMode="Smoothed Voxel Value", QuerySmoothing=1.5)
    check_result(smoothed, "CT head/%s smoothed query" % method, ct_points)
# Histogram CDF with as many bins as the data has values is Exact Box (the Wavelet's
# RTData, rounded to 200 values by the Calculator).
steps = Calculator(Input=wavelet, ResultArrayName="Steps", Function="floor(RTData / 2)")
exact_steps = array_of(run(steps, "Steps", "Exact Box", 3), "AmbientOcclusion")
binned_steps = array_of(run(steps, "Steps", "Histogram CDF", 3, NumberOfBins=1024), "AmbientOcclusion")
check(np.abs(exact_steps - binned_steps).max() <= 1e-6,
      "Wavelet steps: Histogram CDF with a bin per value equals Exact Box (max diff %.2g)"
      % np.abs(exact_steps - binned_steps).max())
Delete(steps)

# Bad input: an error and an empty output, not a crash.
for what, settings in [("Radius 0", dict(Radius=0)), ("NumberOfBins 1", dict(NumberOfBins=1)),
                       ("QuerySmoothing 0", dict(QueryMode="Smoothed Voxel Value", QuerySmoothing=0.0))]:
    bad = VolumetricAmbientOcclusion(Input=ct, **settings)
    bad.UpdatePipeline()
    check(servermanager.Fetch(bad).GetNumberOfPoints() == 0, "%s gives an empty output" % what)
    Delete(bad)

# The project's own phantom source, straight into the filter with default settings
# (Scalars left to the active point scalars).
phantom = AmbientOcclusionHeadPhantom(Dimensions=[48, 44, 40])
default_run = VolumetricAmbientOcclusion(Input=phantom, Radius=4)
default_run.UpdatePipeline()
phantom_ao = servermanager.Fetch(default_run)
check(phantom_ao.GetPointData().GetArray("Density").GetDataTypeAsString() == "short",
      "the phantom is int16 HU")
values = array_of(phantom_ao, "AmbientOcclusion")
check(values.size == 48 * 44 * 40 and 0.0 <= values.min() and values.max() <= 1.0 and values.std() > 0.05,
      "phantom: default run gives AO in [0, 1] with contrast (std %.3f)" % values.std())
Delete(default_run)

# Occlusion Sweeping: properties, outputs on the CT head's skin, and a contour coloured
# by it (the pipeline a user builds).
sweep = OcclusionSweeping(Input=ct, IsoValue=-300.0, OutputOctantVisibility=1, UseGeometryTerm=0)
for name in ["Scalars", "IsoValue", "InsideIsAbove", "NumberOfIterations", "ConvergenceTolerance",
             "UseGeometryTerm", "OctantMask", "Gamma", "Opacity", "OutputOctantVisibility", "Component",
             "NumberOfThreads"]:
    prop = sweep.GetProperty(name)
    check(prop is not None and len(prop.SMProperty.GetDocumentation().GetDescription().strip()) > 20,
          "OcclusionSweeping property %s exists and is documented" % name)
check(list(sweep.OctantMask) == [1] * 8 and sweep.NumberOfIterations == 1 and sweep.InsideIsAbove == 1,
      "OcclusionSweeping defaults: all octants, one pass, inside above")
sweep.Scalars = ["POINTS", "MetaImage"]
swept = servermanager.Fetch(sweep)
distance = array_of(swept, "SignedDistance")
occlusion = array_of(swept, "AmbientOcclusion")
ct_values = array_of(swept, "MetaImage")
check(np.array_equal(distance < 0, ct_values > -300.0), "sweeping: negative distance exactly inside the skin")
check(occlusion.min() >= 0.0 and occlusion.max() <= 1.0 and occlusion.std() > 0.05,
      "sweeping: AO in [0, 1] with contrast (std %.3f)" % occlusion.std())
check(swept.GetPointData().GetArray("OctantVisibility").GetNumberOfComponents() == 8, "sweeping: 8 octants")
skin = Contour(Input=sweep, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[-300.0], ComputeScalars=1)
surface = servermanager.Fetch(skin)
surface_ao = surface.GetPointData().GetArray("AmbientOcclusion")
check(surface.GetNumberOfPoints() > 10000 and surface_ao is not None, "the skin contour carries AmbientOcclusion")
# The skin coloured in one step: Probe Outside Surface samples the sweeping's field a voxel
# and a half outside the skin, so the inside voxels (dark by definition) do not darken it.
lit_skin = ProbeOutsideSurface(Input=skin, Volume=sweep)
check(lit_skin.Distance == 1.5 and lit_skin.Orientation == "Auto", "Probe Outside Surface defaults")
lit = servermanager.Fetch(lit_skin)
lit_ao = array_of(lit, "AmbientOcclusion")
check(lit.GetNumberOfPoints() == surface.GetNumberOfPoints() and lit.GetPointData().GetArray("OctantVisibility"),
      "Probe Outside Surface: every point of the skin, every array of the sweeping")
on_skin = array_of(surface, "AmbientOcclusion")
check(lit_ao.mean() > on_skin.mean() + 0.1 and 0.0 <= lit_ao.min() and lit_ao.max() <= 1.0,
      "the probed skin is lit (mean AO %.3f) where the contour's own is dark (%.3f)" % (lit_ao.mean(), on_skin.mean()))
Delete(lit_skin)
Delete(skin)
Delete(sweep)

# Penner & Mitchell: the pyramid proxy and the Contour -> Isosurface Ambient Occlusion
# pipeline on the CT head's bone, with shadows.
vom = VarianceOcclusionMap(Input=ct)
vom.Scalars = ["POINTS", "MetaImage"]
check(vom.NumberOfThreads == 0 and
      len(vom.GetProperty("NumberOfThreads").SMProperty.GetDocumentation().GetDescription().strip()) > 20,
      "VarianceOcclusionMap property NumberOfThreads exists, defaults to 0 and is documented")
levels = servermanager.Fetch(vom)
check(levels.GetNumberOfBlocks() == 4, "VarianceOcclusionMap: 4 levels", stop=True)
level1 = levels.GetBlock(1)
check(level1.GetDimensions() == (64, 64, 68) and abs(level1.GetSpacing()[0] - 2 * 1.953125) < 1e-9,
      "VarianceOcclusionMap: level 1 halves the resolution (%s)" % (level1.GetDimensions(),))
check(level1.GetPointData().GetArray("Mean") is not None and level1.GetPointData().GetArray("Variance") is not None,
      "VarianceOcclusionMap: Mean and Variance")
Delete(vom)
bone = Contour(Input=ct, ContourBy=["POINTS", "MetaImage"], Isosurfaces=[400.0], ComputeNormals=1)
shaded = IsosurfaceAmbientOcclusion(Input=bone, Volume=ct, ComputeShadows=1, LightDirection=[0.0, -1.0, 1.0])
for name in ["Scalars", "QueryMode", "IsoValue", "NumberOfLevels", "OffsetFactor", "Combine", "Estimator",
             "ComputeShadows", "LightDirection", "NumberOfThreads"]:
    prop = shaded.GetProperty(name)
    check(prop is not None and len(prop.SMProperty.GetDocumentation().GetDescription().strip()) > 20,
          "IsosurfaceAmbientOcclusion property %s exists and is documented" % name)
check(list(shaded.GetProperty("QueryMode").Available) == ["Half Voxel Inside", "Iso Value"] and
      list(shaded.GetProperty("Combine").Available) == ["Max", "Mean"] and
      list(shaded.GetProperty("Estimator").Available) == ["Chebyshev", "Gaussian CDF"],
      "IsosurfaceAmbientOcclusion enumerations")
surface = servermanager.Fetch(shaded)
for name in ["AmbientOcclusion", "Shadow"]:
    from vtkmodules.util.numpy_support import vtk_to_numpy
    values = vtk_to_numpy(surface.GetPointData().GetArray(name))
    check(values.size == surface.GetNumberOfPoints() > 10000 and values.min() >= 0 and values.max() <= 1
          and values.std() > 0.05, "bone surface %s in [0, 1] with contrast (std %.3f)" % (name, values.std()))
# Moving the light re-samples the cached pyramid, it does not rebuild it (ParaView hands the
# filter a new shallow copy of the volume on every update).
def pyramid_builds(proxy):
    return int(re.search(r"PyramidBuilds: (\d+)", str(proxy.GetClientSideObject())).group(1))


builds_before = pyramid_builds(shaded)
shadow_before = vtk_to_numpy(surface.GetPointData().GetArray("Shadow")).copy()
shaded.LightDirection = [1.0, 0.0, 1.0]
moved = servermanager.Fetch(shaded)
check(pyramid_builds(shaded) == builds_before == 1,
      "a light move through pvpython re-samples the pyramid (%d builds before, %d after)"
      % (builds_before, pyramid_builds(shaded)))
check(np.abs(vtk_to_numpy(moved.GetPointData().GetArray("Shadow")) - shadow_before).max() > 0.1,
      "the shadows follow the moved light")
# Ambient Occlusion Shading on both data types, with default settings.
colours = AmbientOcclusionShading(Input=shaded)
lit_surface = servermanager.Fetch(colours)
rgb = lit_surface.GetPointData().GetArray("ShadedRGB")
check(rgb is not None and rgb.GetNumberOfComponents() == 3 and rgb.GetDataTypeAsString() == "unsigned char",
      "AmbientOcclusionShading on the bone surface: ShadedRGB (3 x uint8)")
Delete(colours)
volume_ao = VolumetricAmbientOcclusion(Input=ct, Radius=5, ComputeVariance=1)
volume_ao.Scalars = ["POINTS", "MetaImage"]
lit_volume = AmbientOcclusionShading(Input=volume_ao, ModulateOpacity=1)
for name in ["AmbientOcclusionArray", "Scalars", "ColorPreset", "ScalarRange", "OpacityRamp", "AmbientIntensity",
             "Gamma", "ModulateOpacity", "VarianceMax", "NumberOfThreads"]:
    prop = lit_volume.GetProperty(name)
    check(prop is not None and len(prop.SMProperty.GetDocumentation().GetDescription().strip()) > 20,
          "AmbientOcclusionShading property %s exists and is documented" % name)
rgba_volume = servermanager.Fetch(lit_volume)
rgba = vtk_to_numpy(rgba_volume.GetPointData().GetArray("ShadedRGBA"))
check(rgba.shape == (ct_points, 4) and rgba[:, 3].max() == 255 and rgba[:, 3].min() == 0 and rgba[:, 0].std() > 5,
      "AmbientOcclusionShading on the CT volume: ShadedRGBA with modulated opacity")
Delete(lit_volume)
Delete(volume_ao)
Delete(shaded)
Delete(bone)

# Write and read back (inline binary .vti: this VTK cannot read appended .vti).
final = VolumetricAmbientOcclusion(Input=ct, Method="Gaussian CDF", Radius=5, ComputeVariance=1)
final.UpdatePipeline()
reference = servermanager.Fetch(final)
vti = os.path.join(out_dir, "plugin_ct_ao.vti")
SaveData(vti, proxy=final, DataMode="Binary")
back = read_image(vti)
for name in ["AmbientOcclusion", "Variance", "MetaImage"]:
    check(np.array_equal(array_of(back, name), array_of(reference, name)), "%s survives the .vti round trip" % name)
# One vocabulary: every proxy that reads a volume array takes Scalars = ['POINTS', name];
# a pvpython trace of each filter replays in a fresh session and gives the same arrays.
ResetSession()
LoadPlugin(plugin, ns=globals())
from paraview import smtrace  # noqa: E402
smtrace.start_trace()
traced_source = Wavelet(WholeExtent=[-10, 10, -10, 10, -10, 10])
traced_ao = VolumetricAmbientOcclusion(Input=traced_source, Radius=3, QueryMode="Smoothed Voxel Value")
traced_ao.Scalars = ["POINTS", "RTData"]
traced_sweep = OcclusionSweeping(Input=traced_ao, IsoValue=150.0)
traced_sweep.Scalars = ["POINTS", "RTData"]
traced_map = VarianceOcclusionMap(Input=traced_ao, NumberOfLevels=3)
traced_map.Scalars = ["POINTS", "RTData"]
traced_contour = Contour(Input=traced_source, ContourBy=["POINTS", "RTData"], Isosurfaces=[150.0], ComputeNormals=1)
traced_iso = IsosurfaceAmbientOcclusion(Input=traced_contour, Volume=traced_source, NumberOfLevels=3)
traced_iso.Scalars = ["POINTS", "RTData"]
traced_shading = AmbientOcclusionShading(Input=traced_ao)
traced_shading.Scalars = ["POINTS", "RTData"]
for proxy in (traced_ao, traced_sweep, traced_map, traced_iso, traced_shading):
    proxy.UpdatePipeline()
trace = smtrace.stop_trace()
for proxy, name in ((traced_ao, "VolumetricAmbientOcclusion"), (traced_sweep, "OcclusionSweeping"),
                    (traced_map, "VarianceOcclusionMap"), (traced_iso, "IsosurfaceAmbientOcclusion"),
                    (traced_shading, "AmbientOcclusionShading")):
    check(list(proxy.Scalars) == ["POINTS", "RTData"], "%s: Scalars is ['POINTS', name]" % name)
    check(name in trace, "the trace creates %s" % name)
expected = {name: array_of(servermanager.Fetch(traced_ao), name) for name in ("AmbientOcclusion",)}
expected_rgba = array_of(servermanager.Fetch(traced_shading), "ShadedRGBA")
expected_shadow = array_of(servermanager.Fetch(traced_iso), "AmbientOcclusion")
ResetSession()
LoadPlugin(plugin, ns=globals())
replay = {}
exec(trace, replay)
replayed = {proxy.GetXMLName(): proxy for proxy in GetSources().values()}
check(set(["VolumetricAmbientOcclusion", "OcclusionSweeping", "VarianceOcclusionMap", "IsosurfaceAmbientOcclusion",
           "AmbientOcclusionShading"]) <= set(replayed), "the replayed trace created every filter (%s)" % sorted(replayed),
      stop=True)
check(np.array_equal(array_of(servermanager.Fetch(replayed["VolumetricAmbientOcclusion"]), "AmbientOcclusion"),
                     expected["AmbientOcclusion"]), "the replayed Volumetric AO equals the traced one")
check(np.array_equal(array_of(servermanager.Fetch(replayed["AmbientOcclusionShading"]), "ShadedRGBA"), expected_rgba),
      "the replayed shading equals the traced one")
check(np.array_equal(array_of(servermanager.Fetch(replayed["IsosurfaceAmbientOcclusion"]), "AmbientOcclusion"),
                     expected_shadow), "the replayed isosurface AO equals the traced one")
finish("all plugin checks passed")
