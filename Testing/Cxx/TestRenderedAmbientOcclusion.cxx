// Regression images, rendered with VTK (under Xvfb in the test suite) and compared with
// committed baselines; a constant AO rendered the same way must differ, so the
// comparison can fail.
//   sweeping:   the CT head phantom's skin isosurface coloured by occlusion-sweeping AO;
//   penner:     its bone isosurface coloured by Penner & Mitchell AO times soft shadows;
//   volume:     its volume rendering lit by Gaussian CDF AO (Ruiz et al. Eq. 5);
//   modulation: the same with the opacity modulated by the intensity variance.
//
// Usage: vaoRenderingTest MODE CT.mha BASELINE.png OUTPUT.png [--write-baseline]
#include "vtkAmbientOcclusionShading.h"
#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkOcclusionSweeping.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkActor.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCamera.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkLookupTable.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPNGReader.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProp3D.h"
#include "vtkSmartVolumeMapper.h"

#include "vtkProbeFilter.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWarpVector.h"
#include "vtkWindowToImageFilter.h"
#include <algorithm>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>

namespace
{

/// Renders one prop seen from the front of the head (DICOM LPS: the face looks towards
/// -y), 300 x 300 pixels, off screen.
vtkSmartPointer<vtkImageData> RenderFromTheFront(vtkProp3D* prop, const double center[3])
{
  vtkNew<vtkRenderer> renderer;
  renderer->AddViewProp(prop);
  renderer->SetBackground(0.1, 0.1, 0.2);
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(300, 300);
  window->AddRenderer(renderer);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetFocalPoint(center[0], center[1], center[2]);
  camera->SetPosition(center[0] - 120.0, center[1] - 600.0, center[2] + 60.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  renderer->ResetCamera();
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(grab->GetOutput());
  return image;
}

/// Renders the surface coloured by `array` (grey, 0 black .. 1 white), seen from the front.
vtkSmartPointer<vtkImageData> Render(vtkPolyData* surface, const char* array)
{
  vtkNew<vtkLookupTable> grey;
  grey->SetTableRange(0.0, 1.0);
  grey->SetSaturationRange(0.0, 0.0);
  grey->SetValueRange(0.1, 1.0);
  grey->Build();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(surface);
  mapper->SetLookupTable(grey);
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectColorArray(array);
  mapper->SetScalarRange(0.0, 1.0);
  mapper->ScalarVisibilityOn();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  // Ambient light only: the picture shows the AO field itself, not the lighting.
  actor->GetProperty()->SetAmbient(1.0);
  actor->GetProperty()->SetDiffuse(0.0);
  actor->GetProperty()->SetSpecular(0.0);
  return RenderFromTheFront(actor, surface->GetCenter());
}

/// Volume rendering of the ShadedRGBA array (dependent components: RGB as they are, the
/// alpha byte through an identity opacity function).
vtkSmartPointer<vtkImageData> RenderShadedVolume(vtkImageData* shaded)
{
  vtkNew<vtkSmartVolumeMapper> mapper;
  mapper->SetInputData(shaded);
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectScalarArray("ShadedRGBA");
  vtkNew<vtkPiecewiseFunction> alpha;
  alpha->AddPoint(0.0, 0.0);
  alpha->AddPoint(255.0, 1.0);
  vtkNew<vtkVolumeProperty> property;
  property->IndependentComponentsOff();
  property->SetScalarOpacity(alpha);
  property->ShadeOff(); // the AO is the only lighting
  // Trilinear samples at a quarter of the smallest spacing: nearest-voxel samples at the
  // default distance turn the thin skin into wood-grain rings that hide the AO.
  property->SetInterpolationTypeToLinear();
  const double* h = shaded->GetSpacing();
  mapper->SetAutoAdjustSampleDistances(0);
  mapper->SetSampleDistance(0.25 * std::min({ h[0], h[1], h[2] }));
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  return RenderFromTheFront(volume, shaded->GetCenter());
}

/// Root-mean-square difference of the RGB values (0..255) of two images of one size.
double Difference(vtkImageData* image, vtkImageData* baseline)
{
  vtkDataArray* a = image->GetPointData()->GetScalars();
  vtkDataArray* b = baseline->GetPointData()->GetScalars();
  if (!a || !b || a->GetNumberOfTuples() != b->GetNumberOfTuples())
  {
    return 1e30;
  }
  double sum = 0.0;
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      const double d = a->GetComponent(i, c) - b->GetComponent(i, c);
      sum += d * d;
    }
  }
  return std::sqrt(sum / (3.0 * a->GetNumberOfTuples()));
}

} // namespace

/// The skin (-300 HU) coloured by sweeping AO, sampled one voxel outside the surface.
vtkSmartPointer<vtkPolyData> SweepingSkin(vtkAlgorithmOutput* ct)
{
  vtkNew<vtkOcclusionSweeping> sweep;
  sweep->SetInputConnection(ct);
  sweep->SetIsoValue(-300.0);
  sweep->UseGeometryTermOn(); // irradiance for the surface normal: a convex skin is bright
  vtkNew<vtkFlyingEdges3D> skin;
  skin->SetInputConnection(sweep->GetOutputPort());
  skin->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "MetaImage");
  skin->SetValue(0, -300.0);
  skin->ComputeScalarsOff();
  skin->ComputeNormalsOn();
  // The AO of the surface is the AO just outside it: points moved one voxel outwards
  // (FlyingEdges orients the normals towards lower values: outwards here) sample the
  // field there, away from the inside voxels, whose visibility is dark by definition.
  vtkNew<vtkWarpVector> outwards;
  outwards->SetInputConnection(skin->GetOutputPort());
  outwards->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Normals");
  outwards->SetScaleFactor(2.0); // about one voxel (1.95 x 1.95 x 2 mm)
  vtkNew<vtkProbeFilter> probe;
  probe->SetInputConnection(outwards->GetOutputPort());
  probe->SetSourceConnection(sweep->GetOutputPort());
  probe->Update();
  auto surface = vtkSmartPointer<vtkPolyData>::New();
  surface->DeepCopy(skin->GetOutput());
  vtkDataArray* ao = probe->GetOutput()->GetPointData()->GetArray("AmbientOcclusion");
  ao->SetName("Shade");
  surface->GetPointData()->AddArray(ao);
  return surface;
}

/// The bone (400 HU) coloured by Penner & Mitchell AO times the soft shadow of a light
/// from the front and above.
vtkSmartPointer<vtkPolyData> PennerBone(vtkAlgorithmOutput* ct)
{
  vtkNew<vtkFlyingEdges3D> bone;
  bone->SetInputConnection(ct);
  bone->SetValue(0, 400.0);
  bone->ComputeNormalsOn();
  vtkNew<vtkIsosurfaceAmbientOcclusion> shade;
  shade->SetInputConnection(0, bone->GetOutputPort());
  shade->SetVolumeConnection(ct);
  shade->ComputeShadowsOn();
  shade->SetLightDirection(0.3, -1.0, 1.0);
  shade->Update();
  auto surface = vtkSmartPointer<vtkPolyData>::New();
  surface->DeepCopy(shade->GetOutput());
  vtkDataArray* ao = surface->GetPointData()->GetArray("AmbientOcclusion");
  vtkDataArray* shadow = surface->GetPointData()->GetArray("Shadow");
  if (!ao || !shadow)
  {
    return surface;
  }
  vtkNew<vtkFloatArray> product;
  product->SetName("Shade");
  product->SetNumberOfTuples(surface->GetNumberOfPoints());
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    // Ambient light dimmed by AO, plus direct light dimmed by the shadow.
    product->SetValue(
      i, static_cast<float>(ao->GetComponent(i, 0) * (0.5 + 0.5 * shadow->GetComponent(i, 0))));
  }
  surface->GetPointData()->AddArray(product);
  return surface;
}

/// The CT lit by Gaussian CDF AO at radius 10 (or by a constant AO), shaded with the
/// Bone preset: the skull opaque; with the modulation, the soft tissue shows too, faded
/// where it is homogeneous.
vtkSmartPointer<vtkImageData> AmbientLitVolume(vtkImageData* withAO, bool modulate, bool constantAO)
{
  vtkNew<vtkImageData> input;
  input->ShallowCopy(withAO);
  if (constantAO)
  {
    vtkNew<vtkFloatArray> constant;
    constant->SetName("AmbientOcclusion");
    constant->SetNumberOfTuples(input->GetNumberOfPoints());
    constant->Fill(0.5f);
    input->GetPointData()->AddArray(constant);
  }
  vtkNew<vtkAmbientOcclusionShading> shading;
  shading->SetInputData(input);
  shading->SetColorPreset(vtkAmbientOcclusionShading::BONE);
  shading->SetScalarRange(-200.0, 1200.0);
  shading->SetOpacityRamp(modulate ? -600.0 : 200.0, 1000.0);
  shading->SetAmbientIntensity(1.5);
  shading->SetModulateOpacity(modulate);
  shading->Update();
  return RenderShadedVolume(vtkImageData::SafeDownCast(shading->GetOutput()));
}

int main(int argc, char* argv[])
{
  const std::string mode = argc > 1 ? argv[1] : "";
  if (argc < 5 ||
    (mode != "sweeping" && mode != "penner" && mode != "volume" && mode != "modulation"))
  {
    std::fprintf(stderr,
      "usage: %s sweeping|penner|volume|modulation CT.mha BASELINE.png OUTPUT.png "
      "[--write-baseline]\n",
      argv[0]);
    return 2;
  }
  const char* baselinePath = argv[3];
  const char* outputPath = argv[4];
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(argv[2]);
  // Each mode renders its picture with the real AO and, as the negative control, with a
  // constant one.
  std::function<vtkSmartPointer<vtkImageData>(bool)> render;
  vtkSmartPointer<vtkPolyData> surface;
  vtkNew<vtkImageData> volume;
  if (mode == "sweeping" || mode == "penner")
  {
    surface = mode == "sweeping" ? SweepingSkin(reader->GetOutputPort())
                                 : PennerBone(reader->GetOutputPort());
    if (!surface->GetPointData()->GetArray("Shade") || surface->GetNumberOfPoints() < 1000)
    {
      std::fprintf(stderr, "FAILED: the surface carries no shading\n");
      return 1;
    }
    render = [&surface](bool constantAO)
    {
      if (!constantAO)
      {
        return Render(surface, "Shade");
      }
      vtkNew<vtkFloatArray> constant;
      constant->SetName("Constant");
      constant->SetNumberOfTuples(surface->GetNumberOfPoints());
      constant->Fill(0.5f);
      surface->GetPointData()->AddArray(constant);
      return Render(surface, "Constant");
    };
  }
  else
  {
    vtkNew<vtkVolumetricAmbientOcclusion> ao;
    ao->SetInputConnection(reader->GetOutputPort());
    ao->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
    ao->SetRadius(10);
    ao->ComputeVarianceOn();
    ao->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CPU);
    ao->Update();
    volume->DeepCopy(ao->GetOutput());
    const bool modulate = mode == "modulation";
    render = [&volume, modulate](bool constantAO)
    { return AmbientLitVolume(volume, modulate, constantAO); };
  }
  auto image = render(false);
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(outputPath);
  writer->Write();
  if (argc > 5 && std::strcmp(argv[5], "--write-baseline") == 0)
  {
    writer->SetFileName(baselinePath);
    writer->Write();
  }
  if (!std::ifstream(baselinePath).good())
  {
    std::fprintf(stderr, "FAILED: missing baseline %s\n", baselinePath);
    return 1;
  }
  vtkNew<vtkPNGReader> baselineReader;
  baselineReader->SetFileName(baselinePath);
  baselineReader->Update();
  const double error = Difference(image, baselineReader->GetOutput());
  const double constantError = Difference(render(true), baselineReader->GetOutput());
  std::printf("regression image RMS difference %g (threshold 2), constant-AO RMS difference %g "
              "(must exceed 5); "
              "image %s\n",
    error, constantError, outputPath);
  if (error > 2.0 || constantError < 5.0)
  {
    std::printf("FAILED\n");
    return 1;
  }
  std::printf("passed\n");
  return 0;
}
