// The Transfer Function method through the VTK filter: the opacity as
// vtkPiecewiseFunction::GetValue gives it, the box mean against brute force, the step
// function against Exact Box, re-execution when the function is edited, bad functions.
#include "TestHelpers.h"
#include "VolumetricTestSupport.h"
#include "vtkAmbientOcclusionOpacity.h"

#include "vtkVolumetricAmbientOcclusion.h"

#include "vao/TransferFunction.h"

#include "vtkCallbackCommand.h"
#include "vtkCharArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnsignedShortArray.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>

using namespace vaotest;

namespace
{

/// The module's description of a VTK function (nodes, clamping, log scale and how the VTK
/// in use evaluates them), which the kernel evaluates.
vao::OpacityFunction Nodes(vtkPiecewiseFunction* f)
{
  return vtkAmbientOcclusionOpacity::Nodes(f);
}

/// A random function on [lo, hi]: 1 to 6 points, opacities anywhere in [0, 1] (not
/// monotone), midpoints and sharpness including the ends and VTK's 0.01 / 0.99 switches.
vtkSmartPointer<vtkPiecewiseFunction> RandomFunction(
  std::mt19937& rng, double lo, double hi, bool clamping)
{
  static const double shapes[] = { 0.0, 0.005, 0.01, 0.3, 0.5, 0.99, 0.995, 1.0 };
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 7);
  auto f = vtkSmartPointer<vtkPiecewiseFunction>::New();
  f->AllowDuplicateScalarsOn();
  f->SetClamping(clamping);
  const int points = 1 + static_cast<int>(unit(rng) * 6);
  for (int p = 0; p < points; ++p)
    f->AddPoint(lo + (hi - lo) * unit(rng), std::round(unit(rng) * 8) / 8, shapes[pick(rng)],
      shapes[pick(rng)]);
  return f;
}

/// 1 - the mean of GetValue over the box clipped to the whole extent, in long double.
double BruteForce(vtkImageData* image, vtkPiecewiseFunction* f, const int r[3], int i, int j, int k)
{
  const int* e = image->GetExtent();
  vtkDataArray* values = image->GetPointData()->GetScalars();
  long double sum = 0;
  long count = 0;
  for (int z = std::max(e[4], k - r[2]); z <= std::min(e[5], k + r[2]); ++z)
    for (int y = std::max(e[2], j - r[1]); y <= std::min(e[3], j + r[1]); ++y)
      for (int x = std::max(e[0], i - r[0]); x <= std::min(e[1], i + r[0]); ++x, ++count)
      {
        int ijk[3] = { x, y, z };
        sum += f->GetValue(values->GetTuple1(image->ComputePointId(ijk)));
      }
  return static_cast<double>(1.0L - sum / count);
}

template <class ArrayT>
vtkSmartPointer<vtkImageData> TypedImage(double lo, double hi, unsigned seed)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(-4, 6, 2, 10, 7, 15);
  image->SetSpacing(0.5, 1.0, 2.0);
  vtkNew<ArrayT> values;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(lo, hi);
  SetDensity(image, values,
    [&](int, int, int)
    {
      const double v = uniform(rng);
      return std::is_integral<typename ArrayT::ValueType>::value ? std::floor(v) : v;
    });
  return image;
}

template <class ArrayT>
void CheckAgainstBruteForce(double lo, double hi, unsigned seed)
{
  auto image = TypedImage<ArrayT>(lo, hi, seed);
  std::mt19937 rng(seed);
  for (bool clamping : { true, false })
  {
    auto f = RandomFunction(rng, lo, hi, clamping);
    // Radius 2 world units: 4, 2 and 1 voxels along x, y, z.
    const FilterRun run = RunFilter(image,
      [&](vtkVolumetricAmbientOcclusion* a)
      {
        a->SetMethod(vtkVolumetricAmbientOcclusion::TRANSFER_FUNCTION);
        a->SetRadiusUnits(vtkVolumetricAmbientOcclusion::WORLD);
        a->SetRadius(2.0);
        a->SetOpacityFunction(f);
      });
    ASSERT_TRUE(run.errors.empty()) << run.errors[0];
    vtkDataArray* ao = run.output->GetPointData()->GetArray("AmbientOcclusion");
    ASSERT_NE(ao, nullptr);
    const int r[3] = { 4, 2, 1 };
    const int* e = image->GetExtent();
    double worst = 0;
    vtkIdType id = 0;
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int i = e[0]; i <= e[1]; ++i, ++id)
          worst = std::max(worst, std::abs(ao->GetTuple1(id) - BruteForce(image, f, r, i, j, k)));
    EXPECT_LE(worst, 1e-6)
      << ArrayT::SafeDownCast(image->GetPointData()->GetScalars())->GetDataTypeAsString()
      << " clamping " << clamping;
  }
}

} // namespace

TEST(TransferFunctionAO, OpacityIsVtkPiecewiseFunctionGetValue)
{
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 400; ++trial)
  {
    const bool logScale = trial % 4 == 3;
    const double lo = logScale ? 0.01 : -100.0;
    auto f = RandomFunction(rng, lo, 100.0, trial % 2 == 0);
    f->SetUseLogScale(logScale);
    if (trial % 5 == 4) // a second point at an existing value, as ParaView's editor allows
    {
      double first[4];
      f->GetNodeValue(0, first);
      f->AddPoint(first[0], 1.0 - first[1], 0.5, 0.0);
    }
    const vao::OpacityFunction nodes = Nodes(f);
    std::vector<double> at;
    for (const auto& n : nodes.nodes)
      at.insert(at.end(), { n.x, std::nextafter(n.x, -1e300), std::nextafter(n.x, 1e300) });
    for (int s = 0; s < 50; ++s)
      at.push_back(lo - 10 + 120 * unit(rng));
    for (double x : at)
    {
      if (logScale && x <= 0)
        continue;
      const double expected = f->GetValue(x);
      const double got = vao::evaluateOpacity(nodes, x);
      ASSERT_FALSE(std::isnan(got)) << "at " << x;
      if (std::abs(got - expected) > 1e-12 && worst <= 1e-12)
      {
        std::ostringstream points;
        for (const auto& n : nodes.nodes)
          points << " (" << n.x << ", " << n.y << ", " << n.midpoint << ", " << n.sharpness << ")";
        ADD_FAILURE() << "at " << x << " VTK " << expected << ", ours " << got << "; clamping "
                      << nodes.clamping << " log " << nodes.logScale << ", points" << points.str();
      }
      worst = std::max(worst, std::abs(got - expected));
    }
  }
  EXPECT_LE(worst, 1e-12);
}

TEST(TransferFunctionAO, ManyEvenNodesAreEvaluatedAsVtkSearchesThem)
{
  // VTK 9.3 searches 10^4 or more evenly spaced nodes by interpolation, not bisection: a
  // function sampled from a table (a measured opacity curve) has them.
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (bool clamping : { true, false })
  {
    vtkNew<vtkPiecewiseFunction> f;
    f->SetClamping(clamping);
    const int count = 12000;
    std::vector<double> table(count);
    for (double& y : table)
      y = unit(rng);
    f->BuildFunctionFromTable(-50.0, 70.0, count, table.data());
    const vao::OpacityFunction nodes = Nodes(f);
    double worst = 0.0;
    for (int s = 0; s < 2000; ++s)
    {
      const double x = -55.0 + 130.0 * unit(rng);
      worst = std::max(worst, std::abs(vao::evaluateOpacity(nodes, x) - f->GetValue(x)));
    }
    for (int i = 0; i < count; i += 97)
    {
      double node[4];
      f->GetNodeValue(i, node);
      worst =
        std::max(worst, std::abs(vao::evaluateOpacity(nodes, node[0]) - f->GetValue(node[0])));
    }
    EXPECT_LE(worst, 1e-12) << "clamping " << clamping;
  }
}

TEST(TransferFunctionAO, MatchesBruteForceOnEveryScalarType)
{
  CheckAgainstBruteForce<vtkUnsignedCharArray>(0, 255, 1);
  CheckAgainstBruteForce<vtkCharArray>(-128, 127, 2);
  CheckAgainstBruteForce<vtkShortArray>(-1024, 3071, 3);
  CheckAgainstBruteForce<vtkUnsignedShortArray>(0, 65535, 4);
  CheckAgainstBruteForce<vtkIntArray>(-70000, 70000, 5);
  CheckAgainstBruteForce<vtkFloatArray>(-2.5, 7.0, 6);
  CheckAgainstBruteForce<vtkDoubleArray>(-3e5, 1e5, 7);
}

TEST(TransferFunctionAO, StepFunctionIsExactBoxWithTheIsoValue)
{
  auto image = RandomImage(14, 11, 9, 3);
  for (double c : { -300.0, 100.0, 449.0 })
  {
    vtkNew<vtkPiecewiseFunction> step;
    step->AddPoint(c, 0.0);
    step->AddPoint(c + 1, 1.0);
    const FilterRun tf = RunFilter(image,
      [&](vtkVolumetricAmbientOcclusion* a)
      {
        a->SetMethod(vtkVolumetricAmbientOcclusion::TRANSFER_FUNCTION);
        a->SetRadius(3);
        a->SetOpacityFunction(step);
      });
    const FilterRun box = RunFilter(image,
      [&](vtkVolumetricAmbientOcclusion* a)
      {
        a->SetMethod(vtkVolumetricAmbientOcclusion::EXACT_BOX);
        a->SetRadius(3);
        a->SetQueryMode(vtkVolumetricAmbientOcclusion::ISO_VALUE);
        a->SetIsoValue(c);
      });
    ASSERT_TRUE(tf.errors.empty() && box.errors.empty());
    auto* a = vtkFloatArray::SafeDownCast(tf.output->GetPointData()->GetArray("AmbientOcclusion"));
    auto* b = vtkFloatArray::SafeDownCast(box.output->GetPointData()->GetArray("AmbientOcclusion"));
    ASSERT_TRUE(a && b);
    ASSERT_EQ(a->GetNumberOfValues(), b->GetNumberOfValues());
    EXPECT_EQ(
      0, std::memcmp(a->GetPointer(0), b->GetPointer(0), sizeof(float) * a->GetNumberOfValues()))
      << "iso value " << c;
  }
}

TEST(TransferFunctionAO, EditingTheFunctionReexecutesTheFilter)
{
  auto image = RandomImage(12, 10, 8, 5);
  vtkNew<vtkPiecewiseFunction> f;
  f->AddPoint(-300, 0.0);
  f->AddPoint(900, 1.0);
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputData(image);
  filter->SetMethod(vtkVolumetricAmbientOcclusion::TRANSFER_FUNCTION);
  filter->SetRadius(2);
  filter->SetOpacityFunction(f);
  int executions = 0;
  vtkNew<vtkCallbackCommand> counter;
  counter->SetClientData(&executions);
  counter->SetCallback(
    [](vtkObject*, unsigned long, void* count, void*) { ++*static_cast<int*>(count); });
  filter->AddObserver(vtkCommand::StartEvent, counter);
  filter->Update();
  EXPECT_EQ(executions, 1);
  filter->Update();
  EXPECT_EQ(executions, 1) << "re-executed with nothing changed";
  const std::vector<double> before =
    Values(filter->GetOutput()->GetPointData()->GetArray("AmbientOcclusion"));
  f->AddPoint(300, 0.9, 0.3, 0.4); // an edit in the Color Map Editor
  filter->Update();
  EXPECT_EQ(executions, 2) << "the edited function did not re-execute the filter";
  const std::vector<double> after =
    Values(filter->GetOutput()->GetPointData()->GetArray("AmbientOcclusion"));
  EXPECT_NE(before, after);
  const int r[3] = { 2, 2, 2 };
  const int* e = image->GetExtent();
  vtkIdType id = 0;
  for (int k = e[4]; k <= e[5]; ++k)
    for (int j = e[2]; j <= e[3]; ++j)
      for (int i = e[0]; i <= e[1]; ++i, ++id)
        ASSERT_NEAR(after[id], BruteForce(image, f, r, i, j, k), 1e-6);
  // Another method does not read the function: editing it then re-executes nothing.
  filter->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
  filter->Update();
  EXPECT_EQ(executions, 3);
  f->AddPoint(500, 0.2);
  filter->Update();
  EXPECT_EQ(executions, 3) << "an edit of the unused function re-executed the Gaussian CDF";
}

TEST(TransferFunctionAO, RefusesAMissingOrBadFunction)
{
  auto image = RandomImage(8, 8, 8, 2);
  const auto tf = [](vtkPiecewiseFunction* f)
  {
    return [f](vtkVolumetricAmbientOcclusion* a)
    {
      a->SetMethod(vtkVolumetricAmbientOcclusion::TRANSFER_FUNCTION);
      a->SetOpacityFunction(f);
    };
  };
  ExpectRejected(image, tf(nullptr), "needs an opacity function");
  vtkNew<vtkPiecewiseFunction> empty;
  ExpectRejected(image, tf(empty), "no points");
  vtkNew<vtkPiecewiseFunction> nan;
  nan->AddPoint(0, std::numeric_limits<double>::quiet_NaN());
  ExpectRejected(image, tf(nan), "not finite");
  vtkNew<vtkPiecewiseFunction> above;
  above->AddPoint(0, 0.0);
  above->AddPoint(100, 1.5);
  ExpectRejected(image, tf(above), "[0, 1]");
  vtkNew<vtkPiecewiseFunction> logScale;
  logScale->AddPoint(-10, 0.0);
  logScale->AddPoint(500, 1.0);
  logScale->UseLogScaleOn();
  ExpectRejected(image, tf(logScale), "log scale");
}
