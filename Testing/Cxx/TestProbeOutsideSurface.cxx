// Probe Outside Surface: the sweeping's field sampled just outside its isosurface, against
// a trilinear sampler written here; the side chosen by SignedDistance; bad input.
#include "TestHelpers.h"

#include "vtkOcclusionSweeping.h"
#include "vtkProbeOutsideSurface.h"

#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

using namespace vaotest;

namespace
{

/// A ball over a floor, smooth at the iso value 500, on an anisotropic grid whose extent
/// does not start at 0: the sweeping's AO varies over the ball (the floor shades its
/// underside).
vtkSmartPointer<vtkImageData> BallOverFloor()
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(-4, 27, 3, 34, -2, 27);
  image->SetSpacing(0.7, 0.5, 0.6);
  image->SetOrigin(1.5, -2.0, 0.25);
  vtkNew<vtkFloatArray> values;
  SetDensity(image, values,
    [](int i, int j, int k)
    {
      const double x = 0.7 * i, y = 0.5 * j, z = 0.6 * k;
      const double ball =
        4.0 - std::sqrt((x - 8.0) * (x - 8.0) + (y - 9.5) * (y - 9.5) + (z - 8.5) * (z - 8.5));
      const double floor = 2.5 - z;
      return 500.0 + 400.0 * std::clamp(std::max(ball, floor), -1.0, 1.0);
    });
  return image;
}

vtkSmartPointer<vtkImageData> Swept(vtkImageData* volume)
{
  vtkNew<vtkOcclusionSweeping> sweep;
  sweep->SetInputData(volume);
  sweep->SetIsoValue(500.0);
  sweep->Update();
  return sweep->GetOutput();
}

vtkSmartPointer<vtkPolyData> Contour(vtkImageData* field)
{
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(field);
  contour->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Density");
  contour->SetValue(0, 500.0);
  contour->ComputeNormalsOn();
  contour->InterpolateAttributesOn();
  contour->Update();
  return contour->GetOutput();
}

/// Whether world point x lies in the image's box.
bool Inside(vtkImageData* image, const double x[3])
{
  double b[6];
  image->GetBounds(b);
  return x[0] >= b[0] && x[0] <= b[1] && x[1] >= b[2] && x[1] <= b[3] && x[2] >= b[4] &&
    x[2] <= b[5];
}

struct ProbeRun
{
  vtkSmartPointer<vtkPolyData> output;
  int side = 0;
  std::vector<std::string> errors;
};

ProbeRun Probe(vtkPolyData* surface, vtkImageData* volume,
  const std::function<void(vtkProbeOutsideSurface*)>& set)
{
  vtkNew<vtkProbeOutsideSurface> probe;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(probe);
  probe->SetInputData(0, surface);
  if (volume)
    probe->SetInputData(1, volume);
  set(probe);
  probe->Update();
  return { probe->GetOutput(), probe->GetLastSide(), catcher->Errors };
}

const auto kDefaults = [](vtkProbeOutsideSurface*) {};

} // namespace

TEST(ProbeOutsideSurface, SamplesEveryArrayOutsideTheSurface)
{
  const auto field = Swept(BallOverFloor());
  const auto surface = Contour(field);
  ASSERT_GT(surface->GetNumberOfPoints(), 1000);
  vtkDataArray* normals = surface->GetPointData()->GetNormals();
  ASSERT_NE(normals, nullptr);

  // Contour normals point towards lower values, out of the occluder: sampled along them.
  const ProbeRun along = Probe(surface, field, kDefaults);
  ASSERT_TRUE(along.errors.empty()) << along.errors.front();
  EXPECT_EQ(along.side, 1);

  // The same surface with its normals reversed: SignedDistance turns them back.
  vtkNew<vtkPolyData> reversed;
  reversed->DeepCopy(surface);
  vtkDataArray* flipped = reversed->GetPointData()->GetNormals();
  for (vtkIdType i = 0; i < flipped->GetNumberOfTuples(); ++i)
    for (int c = 0; c < 3; ++c)
      flipped->SetComponent(i, c, -flipped->GetComponent(i, c));
  const ProbeRun back = Probe(reversed, field, kDefaults);
  EXPECT_EQ(back.side, -1);
  // Orientation fixed against the (original) normals samples inside instead.
  const ProbeRun inside = Probe(surface, field,
    [](vtkProbeOutsideSurface* f) { f->SetOrientation(vtkProbeOutsideSurface::REVERSED_NORMALS); });

  const double offset = 1.5 * 0.5;
  for (const char* name : { "AmbientOcclusion", "SignedDistance", "Density" })
  {
    vtkDataArray* truth = field->GetPointData()->GetArray(name);
    vtkDataArray* a = along.output->GetPointData()->GetArray(name);
    vtkDataArray* b = back.output->GetPointData()->GetArray(name);
    vtkDataArray* c = inside.output->GetPointData()->GetArray(name);
    ASSERT_TRUE(truth && a && b && c) << name;
    double worst = 0.0, worstInside = 0.0;
    for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
    {
      double p[3], n[3], out[3], in[3];
      surface->GetPoint(i, p);
      normals->GetTuple(i, n);
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int k = 0; k < 3; ++k)
      {
        out[k] = p[k] + offset * n[k] / length;
        in[k] = p[k] - offset * n[k] / length;
      }
      const double expected = Trilinear(field, Inside(field, out) ? out : p, truth);
      const double expectedInside = Trilinear(field, Inside(field, in) ? in : p, truth);
      const double scale = std::max(1.0, std::abs(expected));
      worst = std::max({ worst, std::abs(a->GetComponent(i, 0) - expected) / scale,
        std::abs(b->GetComponent(i, 0) - expected) / scale });
      worstInside = std::max(worstInside, std::abs(c->GetComponent(i, 0) - expectedInside) / scale);
    }
    EXPECT_LT(worst, 1e-5) << name;
    EXPECT_LT(worstInside, 1e-5) << name;
  }
  // The 8-component octants come along too.
  vtkDataArray* octants = along.output->GetPointData()->GetArray("OctantVisibility");
  EXPECT_TRUE(octants == nullptr || octants->GetNumberOfComponents() == 8);
}

TEST(ProbeOutsideSurface, IsBrighterThanTheFieldOnTheSurfaceItself)
{
  // The reason for the filter: inside the occluder the sweeping's AO is 0, so the field
  // interpolated onto the isosurface is darkened by the inside voxels.
  const auto field = Swept(BallOverFloor());
  const auto surface = Contour(field);
  const ProbeRun run = Probe(surface, field, kDefaults);
  vtkDataArray* onSurface = surface->GetPointData()->GetArray("AmbientOcclusion");
  vtkDataArray* outside = run.output->GetPointData()->GetArray("AmbientOcclusion");
  ASSERT_TRUE(onSurface && outside);
  double meanOn = 0.0, meanOut = 0.0;
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    meanOn += onSurface->GetComponent(i, 0);
    meanOut += outside->GetComponent(i, 0);
  }
  meanOn /= surface->GetNumberOfPoints();
  meanOut /= surface->GetNumberOfPoints();
  EXPECT_GT(meanOut, meanOn + 0.1) << meanOn << " " << meanOut;
  // Distance 0 is the field on the surface.
  const ProbeRun zero =
    Probe(surface, field, [](vtkProbeOutsideSurface* f) { f->SetDistance(0.0); });
  vtkDataArray* same = zero.output->GetPointData()->GetArray("AmbientOcclusion");
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); i += 97)
    EXPECT_NEAR(same->GetComponent(i, 0), onSurface->GetComponent(i, 0), 1e-5);
}

TEST(ProbeOutsideSurface, RejectsBadInputWithAClearError)
{
  const auto field = Swept(BallOverFloor());
  const auto surface = Contour(field);
  const auto expectRejected = [&](vtkPolyData* s, vtkImageData* v,
                                const std::function<void(vtkProbeOutsideSurface*)>& set,
                                const std::string& words)
  {
    const ProbeRun run = Probe(s, v, set);
    ASSERT_FALSE(run.errors.empty()) << words;
    EXPECT_NE(run.errors.front().find(words), std::string::npos) << run.errors.front();
    EXPECT_EQ(run.output->GetNumberOfPoints(), 0) << words;
  };
  vtkNew<vtkPolyData> bare;
  bare->ShallowCopy(surface);
  bare->GetPointData()->SetNormals(nullptr);
  bare->GetPointData()->RemoveArray("Normals");
  expectRejected(bare, field, kDefaults, "no point normals");
  expectRejected(
    surface, field, [](vtkProbeOutsideSurface* f) { f->SetDistance(-1.0); }, "Distance");
  expectRejected(
    surface, field, [](vtkProbeOutsideSurface* f) { f->SetDistance(std::nan("")); }, "Distance");
  expectRejected(
    surface, field, [](vtkProbeOutsideSurface* f) { f->SetDistance(INFINITY); }, "Distance");
  expectRejected(
    surface, field, [](vtkProbeOutsideSurface* f) { f->SetOrientation(7); }, "Orientation");
  vtkNew<vtkImageData> empty;
  empty->CopyStructure(field);
  expectRejected(surface, empty, kDefaults, "no point arrays");
  // A volume array that does not fit its points would be read past its end by the probe.
  for (vtkIdType tuples : { vtkIdType(7), field->GetNumberOfPoints() + 1 })
    expectRejected(surface,
      vtkImageData::SafeDownCast(WithPointArrayResized(field, "AmbientOcclusion", tuples)),
      kDefaults, "Array 'AmbientOcclusion' has " + std::to_string(tuples) + " tuples");
  vtkNew<vtkPolyData> shortNormals;
  shortNormals->DeepCopy(surface);
  shortNormals->GetPointData()->GetNormals()->SetNumberOfTuples(5);
  expectRejected(shortNormals, field, kDefaults, "tuples");
  // A surface with no points is no error: an empty result.
  vtkNew<vtkPolyData> nothing;
  const ProbeRun none = Probe(nothing, field, kDefaults);
  EXPECT_TRUE(none.errors.empty());
  EXPECT_EQ(none.output->GetNumberOfPoints(), 0);
}
