"""Figures of the three papers' uses of ambient occlusion, rendered with the plugin in pvpython.

Usage (Debian's ParaView renders through X even offscreen: without a display, run it
under Xvfb, package xvfb):

    xvfb-run -a pvpython --force-offscreen-rendering Examples/figures.py PLUGIN OUTDIR [CT.mha] [--quick]

For the generated head phantom (128^3; 64^3 with --quick) and, when CT.mha is given, for
that CT head (int16 Hounsfield units), it writes eight PNGs per data set, each a row of
panels seen from the front (the face looks towards -y, LPS; view up +z):

    ruiz_ambient_lighting_<data>.png    volume rendering: no AO, Chebyshev, CDF Reconstruction,
                                        Gaussian CDF (R = 10) as ambient light (Ruiz et al. Eq. 5)
    ruiz_opacity_modulation_<data>.png  Gaussian CDF ambient light without and with opacity
                                        modulation by the intensity variance (Ruiz et al. 4.2)
    accuracy_exact_gaussian_histogram_<data>.png
                                        the same light from Exact Box, Gaussian CDF and
                                        Histogram CDF (R = 10): the paper's estimator against ours
    transfer_function_<data>.png        soft tissue shown, bone transparent: ambient light from
                                        the data's order (Histogram CDF) and from the opacity
                                        the rendering uses (Transfer Function), R = 10
    rays_<data>.png                     the bone shown: ParaView's own (unlit) volume rendering,
                                        then lit by Histogram CDF, Transfer Function, Rays and
                                        Exact Rays through the bone's opacity (the AO a ray
                                        tracer shows)
    apply_<data>.png                    what Apply shows with every default (as Show() in
                                        pvpython): Volumetric AO and Occlusion Sweeping (iso -300)
                                        as a Slice, the Shading as a Volume, Isosurface AO on a
                                        bone Contour (400) and Probe Outside Surface on the skin
    singh_sweeping_<data>.png           the skin coloured by occlusion sweeping: skylight, the
                                        upper four octants (overcast), one octant (a shadow)
    penner_bone_<data>.png              the bone: diffuse light only, isosurface AO, AO x shadow

Each PNG is read back and checked not to be blank; the script exits non-zero otherwise.
"""
import os
import sys
import time

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager
import numpy as np
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.util import numpy_support

PANEL = 300                 # pixels per panel (square)
SKIN_HU = -300.0
BONE_HU = 400.0


def usage():
    sys.stderr.write(__doc__)
    sys.exit(2)


args = [a for a in sys.argv[1:] if not a.startswith("--")]
quick = "--quick" in sys.argv[1:]
if len(args) < 2:
    usage()
plugin, out_dir = args[0], args[1]
ct_path = args[2] if len(args) > 2 else None
os.makedirs(out_dir, exist_ok=True)
LoadPlugin(plugin, ns=globals())

# A ParaView built for X (Debian's) aborts without a display; say how to run instead.
import vtkmodules.vtkRenderingOpenGL2 as _gl  # noqa: E402
if not os.environ.get("DISPLAY") and not any(hasattr(_gl, w) for w in ("vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow")):
    sys.exit("no X display, and this ParaView renders through X: run\n"
             "    xvfb-run -a pvpython --force-offscreen-rendering " + " ".join(sys.argv))

view = CreateView("RenderView")
view.ViewSize = [PANEL, PANEL]
view.OrientationAxesVisibility = 0
view.Background = [0.1, 0.1, 0.2]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
SetActiveView(view)
failures = []


# --------------------------------------------------------------------------------------
# Helpers
def hide_all():
    for proxy in list(GetSources().values()):
        Hide(proxy, view)


def label(text):
    """A caption in the panel's upper left corner (hidden with the panel's data)."""
    caption = Text(Text=text)
    display = Show(caption, view)
    display.WindowLocation = "Upper Left Corner"
    display.FontSize = 14
    display.Color = [1.0, 1.0, 1.0]
    return caption


def front_camera(bounds):
    """The face looks towards -y: look at it from the front, a little from the right and above."""
    c = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
    camera = view.GetActiveCamera()
    camera.SetFocalPoint(c)
    camera.SetPosition(c[0] - 120.0, c[1] - 600.0, c[2] + 60.0)
    camera.SetViewUp(0.0, 0.0, 1.0)
    view.CameraParallelProjection = 0
    view.ResetCamera(bounds[0], bounds[1], bounds[2], bounds[3], bounds[4], bounds[5])
    camera.Zoom(1.25)


def grab(path):
    Render(view)
    SaveScreenshot(path, view, ImageResolution=[PANEL, PANEL])
    return path


def read_png(path):
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    dims = image.GetDimensions()
    scalars = image.GetPointData().GetScalars()
    if scalars is None or dims[0] < 2:
        return None
    pixels = numpy_support.vtk_to_numpy(scalars).reshape(dims[1], dims[0], -1)
    return pixels[:, :, :3]


def combine(panel_paths, path):
    """The panels side by side in one PNG (then removed), read back and checked."""
    panels = [read_png(p) for p in panel_paths]
    if any(p is None for p in panels):
        failures.append("%s: a panel could not be read" % path)
        return
    row = np.ascontiguousarray(np.concatenate(panels, axis=1).astype(np.uint8))
    image = vtkImageData()
    image.SetDimensions(row.shape[1], row.shape[0], 1)
    flat = numpy_support.numpy_to_vtk(row.reshape(-1, 3), deep=True)
    flat.SetName("RGB")
    image.GetPointData().SetScalars(flat)
    writer = vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputData(image)
    writer.Write()
    for p in panel_paths:
        os.remove(p)
    back = read_png(path)
    if back is None or back.shape[1] != PANEL * len(panel_paths):
        failures.append("%s was not written" % path)
        return
    # Not blank: every panel must show something besides the background.
    for i in range(len(panel_paths)):
        std = float(back[:, i * PANEL:(i + 1) * PANEL].std())
        if std < 5.0:
            failures.append("%s: panel %d is blank (pixel std %.2f)" % (path, i + 1, std))
    print("wrote %s (%d panels, %.0f KB)" % (path, len(panel_paths), os.path.getsize(path) / 1024.0))


def bounds_of(proxy):
    proxy.UpdatePipeline()
    return proxy.GetDataInformation().GetBounds()


def grey_lut(name):
    lut = GetColorTransferFunction(name)
    lut.ApplyPreset("Grayscale", True)
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RescaleTransferFunction(0.0, 1.0)
    return lut


# --------------------------------------------------------------------------------------
# Figures
SHADING_ARGS = dict(ColorPreset="Bone", ScalarRange=[-600.0, 1500.0], OpacityRamp=[-300.0, 1500.0])


def render_rgba(shaded, text, path, bounds, spacing):
    """A volume rendering of Ambient Occlusion Shading's RGBA, seen from the front."""
    hide_all()
    display = Show(shaded, view)
    display.SetRepresentationType("Volume")
    ColorBy(display, ("POINTS", "ShadedRGBA"))
    display.MapScalars = 0
    # Dependent components: colour = RGB, opacity = the opacity function of A (0..255).
    pwf = GetOpacityTransferFunction("ShadedRGBA")
    GetColorTransferFunction("ShadedRGBA").AutomaticRescaleRangeMode = "Never"
    pwf.Points = [0.0, 0.0, 0.5, 0.0, 60.0, 0.03, 0.5, 0.0, 255.0, 1.0, 0.5, 0.0]
    display.ScalarOpacityUnitDistance = spacing
    label(text)
    front_camera(bounds)
    return grab(path)


def accuracy(source, array, tag, spacing):
    """The same ambient lighting from Exact Box, the paper's Gaussian CDF and Histogram CDF."""
    bounds = bounds_of(source)
    panels = []
    for i, method in enumerate(["Exact Box", "Gaussian CDF", "Histogram CDF"]):
        t0 = time.time()
        ao = VolumetricAmbientOcclusion(Input=source, Method=method, Radius=10, QueryMode="Voxel Value")
        ao.Scalars = ["POINTS", array]
        shaded = AmbientOcclusionShading(Input=ao, **SHADING_ARGS)
        shaded.Scalars = ["POINTS", array]
        panels.append(render_rgba(shaded, method + ", R = 10", os.path.join(out_dir, "_panel%d.png" % i),
                                  bounds, spacing))
        print("  accuracy %-20s %.1f s" % (method, time.time() - t0))
    combine(panels, os.path.join(out_dir, "accuracy_exact_gaussian_histogram_%s.png" % tag))


# Soft tissue shown, bone (above 300 HU) transparent: ParaView's opacity points
# (value, opacity, midpoint, sharpness).
TISSUE_OPACITY = [-1000.0, 0.0, 0.5, 0.0, -500.0, 0.0, 0.5, 0.0, -200.0, 0.4, 0.5, 0.0, 250.0, 0.4, 0.5, 0.0,
                  300.0, 0.0, 0.5, 0.0, 3000.0, 0.0, 0.5, 0.0]


def transfer_function(source, array, tag, spacing):
    """The same soft-tissue rendering lit by the data-order AO and by the transfer-function AO:
    the first darkens the tissue next to the transparent bone, the second does not."""
    bounds = bounds_of(source)
    tissue = GetOpacityTransferFunction(array)
    tissue.Points = TISSUE_OPACITY
    panels = []
    for i, method in enumerate(["Histogram CDF", "Transfer Function"]):
        t0 = time.time()
        ao = VolumetricAmbientOcclusion(Input=source, Method=method, Radius=10, QueryMode="Voxel Value")
        ao.Scalars = ["POINTS", array]
        if method == "Transfer Function":
            ao.OpacityFunction = tissue
        shaded = AmbientOcclusionShading(Input=ao, OpacityTransferFunction=tissue, ColorPreset="Bone",
                                         ScalarRange=[-400.0, 400.0])
        shaded.Scalars = ["POINTS", array]
        text = "AO by value (Histogram CDF)" if i == 0 else "AO by opacity (Transfer Function)"
        panels.append(render_rgba(shaded, text, os.path.join(out_dir, "_panel%d.png" % i), bounds, spacing))
        print("  transfer function %-20s %.1f s" % (method, time.time() - t0))
    combine(panels, os.path.join(out_dir, "transfer_function_%s.png" % tag))


# The bone shown, soft tissue faint: ParaView's opacity points.
BONE_OPACITY = [-1000.0, 0.0, 0.5, 0.0, 100.0, 0.0, 0.5, 0.0, 300.0, 0.15, 0.5, 0.0, 1200.0, 0.8, 0.5, 0.0]


def rays(source, array, tag, spacing):
    """The bone as ParaView renders it (no AO), then lit by the AO of the value order
    (Histogram CDF), of the box's opacity (Transfer Function) and of the rays through the
    opacity (Rays, and Exact Rays: what a ray tracer shows)."""
    bounds = bounds_of(source)
    bone = GetOpacityTransferFunction(array)
    bone.Points = BONE_OPACITY
    hide_all()
    display = Show(source, view)
    display.SetRepresentationType("Volume")
    ColorBy(display, ("POINTS", array))
    # ParaView's counterpart of the Shading's "Bone" colours.
    colors = GetColorTransferFunction(array)
    colors.ApplyPreset("bone_Matlab", True)
    colors.AutomaticRescaleRangeMode = "Never"
    colors.RescaleTransferFunction(-600.0, 1500.0)
    display.ScalarOpacityUnitDistance = spacing
    display.SetScalarBarVisibility(view, False)
    label("ParaView, no AO")
    front_camera(bounds)
    panels = [grab(os.path.join(out_dir, "_panel0.png"))]
    radius = 4 if quick else 6
    for i, method in enumerate(["Histogram CDF", "Transfer Function", "Rays", "Exact Rays"]):
        t0 = time.time()
        ao = VolumetricAmbientOcclusion(Input=source, Method=method, Radius=radius, QueryMode="Voxel Value")
        ao.Scalars = ["POINTS", array]
        if method != "Histogram CDF":
            ao.OpacityFunction = bone
        if method == "Exact Rays" and quick:
            ao.RayCount = 16
        shaded = AmbientOcclusionShading(Input=ao, OpacityTransferFunction=bone, ColorPreset="Bone",
                                         ScalarRange=[-600.0, 1500.0])
        shaded.Scalars = ["POINTS", array]
        panels.append(render_rgba(shaded, "%s, R = %d" % (method, radius),
                                  os.path.join(out_dir, "_panel%d.png" % (i + 1)), bounds, spacing))
        print("  rays %-20s %.1f s" % (method, time.time() - t0))
    combine(panels, os.path.join(out_dir, "rays_%s.png" % tag))


def apply_defaults(source, array, tag):
    """Each filter as Apply (or Show() in pvpython) displays it, every property at its default,
    in a fresh camera as the GUI resets it."""
    panels = []
    ao = VolumetricAmbientOcclusion(Input=source)
    sweep = OcclusionSweeping(Input=source, IsoValue=SKIN_HU)
    shading = AmbientOcclusionShading(Input=ao)
    bone = Contour(Input=source, ContourBy=["POINTS", array], Isosurfaces=[BONE_HU], ComputeNormals=1)
    iso = IsosurfaceAmbientOcclusion(Input=bone, Volume=source)
    skin = Contour(Input=source, ContourBy=["POINTS", array], Isosurfaces=[SKIN_HU], ComputeNormals=1)
    probe = ProbeOutsideSurface(Input=skin, Volume=sweep)
    for i, (proxy, text) in enumerate([(ao, "Volumetric AO"), (sweep, "Occlusion Sweeping"),
                                       (shading, "AO Shading"), (iso, "Isosurface AO"),
                                       (probe, "Probe Outside Surface")]):
        t0 = time.time()
        hide_all()
        Show(proxy, view)
        # A new view's camera: looking down -z, y up.
        view.CameraPosition = [0.0, 0.0, 1.0]
        view.CameraFocalPoint = [0.0, 0.0, 0.0]
        view.CameraViewUp = [0.0, 1.0, 0.0]
        view.ResetCamera()
        label(text)
        panels.append(grab(os.path.join(out_dir, "_panel%d.png" % i)))
        print("  apply %-22s %.1f s" % (text, time.time() - t0))
    combine(panels, os.path.join(out_dir, "apply_%s.png" % tag))


def ruiz(source, array, tag, spacing):
    """Volume rendering lit by AO alone (Ruiz et al. Eq. 5): RGBA from Ambient Occlusion Shading."""
    bounds = bounds_of(source)
    shading_args = SHADING_ARGS

    methods = [("no AO", None), ("Chebyshev", "Chebyshev"), ("CDF Reconstruction", "CDF Reconstruction"),
               ("Gaussian CDF", "Gaussian CDF")]
    panels = []
    gaussian = None
    for i, (text, method) in enumerate(methods):
        t0 = time.time()
        ao = VolumetricAmbientOcclusion(Input=source, Method=method or "Gaussian CDF", Radius=10,
                                        QueryMode="Voxel Value", ComputeVariance=1)
        ao.Scalars = ["POINTS", array]
        if method is None:
            ones = Calculator(Input=ao, ResultArrayName="Open", Function="1", ResultArrayType="Float")
            shaded = AmbientOcclusionShading(Input=ones, AmbientOcclusionArray="Open", **shading_args)
        else:
            shaded = AmbientOcclusionShading(Input=ao, **shading_args)
            if method == "Gaussian CDF":
                gaussian = ao
        shaded.Scalars = ["POINTS", array]
        panels.append(render_rgba(shaded, text if method is None else text + ", R = 10",
                                  os.path.join(out_dir, "_panel%d.png" % i), bounds, spacing))
        print("  ruiz %-20s %.1f s" % (text, time.time() - t0))
    combine(panels, os.path.join(out_dir, "ruiz_ambient_lighting_%s.png" % tag))

    panels = []
    for i, modulate in enumerate([0, 1]):
        # Soft tissue made visible (the ramp starts at -600 HU) so that the modulation has
        # something to fade: homogeneous regions (s2 << s2max) become transparent. In the
        # R = 10 boxes of the CT head the standard deviation is ~320 HU (median) in soft
        # tissue and ~470 HU at bone: s2max = 600^2 fades the first and keeps the second.
        shaded = AmbientOcclusionShading(Input=gaussian, ModulateOpacity=modulate, VarianceMax=600.0 ** 2,
                                         **dict(shading_args, OpacityRamp=[-600.0, 1500.0]))
        shaded.Scalars = ["POINTS", array]
        panels.append(render_rgba(shaded, "Gaussian CDF, opacity %s" % ("x variance" if modulate else "as is"),
                                  os.path.join(out_dir, "_panel%d.png" % i), bounds, spacing))
    combine(panels, os.path.join(out_dir, "ruiz_opacity_modulation_%s.png" % tag))


def singh(source, array, tag, spacing):
    """The skin coloured by occlusion sweeping AO, sampled one voxel outside the surface."""
    masks = [("skylight (8 octants)", [1] * 8), ("overcast (upper 4 octants)", [0, 0, 0, 0, 1, 1, 1, 1]),
             ("one octant (front, above, right)", [0, 0, 0, 0, 1, 0, 0, 0])]
    lut = grey_lut("Shade")
    panels = []
    for i, (text, mask) in enumerate(masks):
        t0 = time.time()
        sweep = OcclusionSweeping(Input=source, IsoValue=SKIN_HU, UseGeometryTerm=1, OctantMask=mask)
        sweep.Scalars = ["POINTS", array]
        skin = Contour(Input=source, ContourBy=["POINTS", array], Isosurfaces=[SKIN_HU], ComputeNormals=1,
                       ComputeScalars=0)
        # The field 1.5 voxels outside the skin, away from the inside voxels (dark by
        # definition), on the skin's points.
        shade = ProbeOutsideSurface(Input=skin, Volume=sweep, Distance=1.5)
        hide_all()
        display = Show(shade, view)
        ColorBy(display, ("POINTS", "AmbientOcclusion"))
        display.LookupTable = lut
        display.Ambient = 1.0
        display.Diffuse = 0.0
        display.Specular = 0.0
        label(text)
        front_camera(bounds_of(skin))
        panels.append(grab(os.path.join(out_dir, "_panel%d.png" % i)))
        print("  singh %-32s %.1f s" % (text, time.time() - t0))
    combine(panels, os.path.join(out_dir, "singh_sweeping_%s.png" % tag))


def penner(source, array, tag):
    """The bone: diffuse light only, isosurface AO, AO times the soft shadow."""
    t0 = time.time()
    bone = Contour(Input=source, ContourBy=["POINTS", array], Isosurfaces=[BONE_HU], ComputeNormals=1,
                   ComputeScalars=0)
    iso = IsosurfaceAmbientOcclusion(Input=bone, Volume=source, ComputeShadows=1,
                                     LightDirection=[0.3, -1.0, 1.0])
    iso.Scalars = ["POINTS", array]
    # Ambient light dimmed by AO plus direct light dimmed by the shadow (as the C++ test).
    shade = Calculator(Input=iso, ResultArrayName="Shade", Function="AmbientOcclusion*(0.5+0.5*Shadow)")
    bounds = bounds_of(bone)
    lut = grey_lut("PennerShade")
    panels = []

    hide_all()
    display = Show(bone, view)
    display.ColorArrayName = ["POINTS", ""]
    display.AmbientColor = [1.0, 1.0, 1.0]
    display.DiffuseColor = [1.0, 1.0, 1.0]
    display.Ambient = 0.35
    display.Diffuse = 0.65
    display.Specular = 0.0
    label("diffuse light only")
    front_camera(bounds)
    panels.append(grab(os.path.join(out_dir, "_panel0.png")))

    for i, (text, arr) in enumerate([("ambient occlusion", "AmbientOcclusion"),
                                     ("AO x soft shadow", "Shade")]):
        hide_all()
        display = Show(shade, view)
        ColorBy(display, ("POINTS", arr))
        display.LookupTable = lut
        # The AO (and shadow) dim the same diffuse light as the first panel, plus ambient light.
        display.Ambient = 0.35
        display.Diffuse = 0.65
        display.Specular = 0.0
        label(text)
        front_camera(bounds)
        panels.append(grab(os.path.join(out_dir, "_panel%d.png" % (i + 1))))
    combine(panels, os.path.join(out_dir, "penner_bone_%s.png" % tag))
    print("  penner %.1f s" % (time.time() - t0))


def figures(source, array, tag):
    t0 = time.time()
    source.UpdatePipeline()
    info = source.GetDataInformation()
    extent = info.GetExtent()
    bounds = info.GetBounds()
    spacing = max((bounds[2 * i + 1] - bounds[2 * i]) / max(extent[2 * i + 1] - extent[2 * i], 1)
                  for i in range(3))
    print("%s: %d x %d x %d voxels, spacing %.2f mm" % (tag, extent[1] - extent[0] + 1, extent[3] - extent[2] + 1,
                                                        extent[5] - extent[4] + 1, spacing))
    apply_defaults(source, array, tag)
    ruiz(source, array, tag, spacing)
    accuracy(source, array, tag, spacing)
    transfer_function(source, array, tag, spacing)
    rays(source, array, tag, spacing)
    singh(source, array, tag, spacing)
    penner(source, array, tag)
    print("%s: %.1f s" % (tag, time.time() - t0))


size = 64 if quick else 128
phantom = AmbientOcclusionHeadPhantom(Dimensions=[size, size, size])
figures(phantom, "Density", "phantom")
if ct_path:
    ct = OpenDataFile(ct_path)
    ct.UpdatePipeline()
    names = ct.PointData.keys()
    if not names:
        failures.append("%s has no point array" % ct_path)
    else:
        figures(ct, names[0], "ct")

for f in failures:
    print("FAILED: %s" % f)
sys.stdout.flush()
sys.stderr.flush()
# os._exit: pvpython 5.11 may crash while tearing down the offscreen render view at exit,
# which would hide the result.
os._exit(1 if failures else 0)
