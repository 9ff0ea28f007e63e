# Run inside the ParaView GUI's Python shell by AmbientOcclusionMenu.xml, after the
# playback built the pipeline through the menus. It writes status.txt, whose last line is
# VAO_GUI_OK only if every check passed (the shell swallows exceptions, so the CMake
# driver RunGUITest.cmake reads the status file), and a screenshot of the render view.
import os
import traceback
from paraview.simple import (GetActiveViewOrCreate, GetColorTransferFunction, GetDisplayProperties,
                             GetScalarBar, GetSources, Hide, SaveScreenshot, Show)

out_dir = VAO_GUI_OUTPUT_DIR  # noqa: F821 (given by the exec() in the playback)
lines = []
try:
    by_xml = {}
    for (name, _), proxy in GetSources().items():
        by_xml[proxy.GetXMLName()] = proxy
        lines.append('source %s (%s)' % (name, proxy.GetXMLName()))
    for xml_name in ('AmbientOcclusionHeadPhantom', 'VolumetricAmbientOcclusion',
                     'OcclusionSweeping', 'VarianceOcclusionMap', 'AmbientOcclusionShading'):
        if xml_name not in by_xml:
            raise RuntimeError('the GUI did not create %s' % xml_name)
    vao = by_xml['VolumetricAmbientOcclusion']
    # Applied with its defaults on the shipped CT head, opened before it.
    if vao.Input.GetXMLName() != 'MetaImageReader':
        raise RuntimeError('Volumetric AO was applied on %s, not on the CT head' % vao.Input.GetXMLName())
    # The filter ran when Apply was pressed: its output carries the openness array.
    info = vao.PointData['AmbientOcclusion']
    lo, hi = info.GetRange()
    lines.append('AmbientOcclusion range %g %g over %d points'
                 % (lo, hi, vao.GetDataInformation().GetNumberOfPoints()))
    if not (0.0 <= lo < hi <= 1.0):
        raise RuntimeError('AmbientOcclusion range [%g, %g] is not inside [0, 1]' % (lo, hi))

    # The panel's layout: property groups, sliders (range domains with both ends), and
    # advanced properties hidden from the default view.
    groups = [vao.SMProxy.GetPropertyGroup(i).GetXMLLabel() for i in range(vao.SMProxy.GetNumberOfPropertyGroups())]
    lines.append('VolumetricAmbientOcclusion groups %s' % groups)
    for label in ('Input', 'Method', 'Neighbourhood', 'Query', 'Output', 'Performance'):
        if label not in groups:
            raise RuntimeError('no property group %s in the panel (%s)' % (label, groups))
    for name in ('Radius', 'QuerySmoothing'):
        domain = vao.GetProperty(name).SMProperty.FindDomain('vtkSMDoubleRangeDomain')
        if not (domain and domain.GetMinimumExists(0) and domain.GetMaximumExists(0)):
            raise RuntimeError('%s has no slider range' % name)
        lines.append('%s slider %g..%g' % (name, domain.GetMinimum(0), domain.GetMaximum(0)))
    for name in ('Backend', 'NumberOfThreads', 'Component'):
        if vao.GetProperty(name).SMProperty.GetPanelVisibility() != 'advanced':
            raise RuntimeError('%s is not an advanced property' % name)

    # What Apply showed, untouched: each filter's AO (not an Outline), the Shading's
    # colours as they are, without a colour legend for them.
    view = GetActiveViewOrCreate('RenderView')
    for xml_name, kind, array in (('VolumetricAmbientOcclusion', 'Slice', 'AmbientOcclusion'),
                                  ('OcclusionSweeping', 'Slice', 'AmbientOcclusion'),
                                  ('AmbientOcclusionShading', 'Volume', 'ShadedRGBA')):
        display = GetDisplayProperties(by_xml[xml_name], view)
        lines.append('%s shown as %s coloured by %s' % (xml_name, display.Representation,
                                                        list(display.ColorArrayName)))
        if display.Representation != kind or list(display.ColorArrayName) != ['POINTS', array]:
            raise RuntimeError('%s after Apply: %s coloured by %s, not %s coloured by %s'
                               % (xml_name, display.Representation, list(display.ColorArrayName), kind, array))
    points = list(GetColorTransferFunction('AmbientOcclusion').RGBPoints)
    lines.append('AmbientOcclusion map %s' % points)
    if points[0] != 0.0 or points[-4] != 1.0 or any(
            points[i + 1] != points[i + 2] or points[i + 1] != points[i + 3] for i in range(0, len(points), 4)):
        raise RuntimeError('the AmbientOcclusion map is not grey over [0, 1]: %s' % points)
    shading = GetDisplayProperties(by_xml['AmbientOcclusionShading'], view)
    if shading.MapScalars != 0:
        raise RuntimeError('the Shading is shown through a colour map (Map Scalars on)')
    if GetScalarBar(GetColorTransferFunction('ShadedRGBA'), view).Visibility:
        raise RuntimeError('a colour legend is shown for ShadedRGBA, whose colours are not mapped')

    for proxy in GetSources().values():
        Hide(proxy, view)
    Show(vao, view)
    view.ResetCamera()
    png = os.path.join(out_dir, 'AmbientOcclusionGUI.png')
    SaveScreenshot(png, view, ImageResolution=[800, 600])
    if not os.path.isfile(png) or os.path.getsize(png) == 0:
        raise RuntimeError('no screenshot written to %s' % png)
    # What the view shows: the grey slice of the AO fills the middle of the view, with
    # many grey levels (an Outline or a one-colour slice would have a handful).
    from vtkmodules.vtkIOImage import vtkPNGReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    reader = vtkPNGReader()
    reader.SetFileName(png)
    reader.Update()
    w, h, _ = reader.GetOutput().GetDimensions()
    rgb = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
    middle = rgb[h // 3:2 * h // 3, w // 3:2 * w // 3].astype(int)
    grey = (middle[:, :, 0] == middle[:, :, 1]) & (middle[:, :, 1] == middle[:, :, 2])
    levels = len(set(middle[grey][:, 0].tolist()))
    lines.append('the middle of the view: %.0f%% grey pixels, %d grey levels' % (100.0 * grey.mean(), levels))
    if grey.mean() < 0.9 or levels < 32:
        raise RuntimeError('the view does not show a grey AO slice (%.0f%% grey, %d levels)'
                           % (100.0 * grey.mean(), levels))
    lines.append('screenshot %s' % png)
    lines.append('VAO_GUI_OK')
except Exception:
    lines.append('VAO_GUI_FAILED')
    lines.append(traceback.format_exc())
with open(os.path.join(out_dir, 'status.txt'), 'w') as f:
    f.write('\n'.join(lines) + '\n')
