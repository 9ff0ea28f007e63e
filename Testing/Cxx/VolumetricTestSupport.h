// Helpers of the tests of vtkVolumetricAmbientOcclusion: a random image, one filter run
// with its messages, and the check of a rejected input.
#pragma once

#include "TestHelpers.h"

#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"

#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <string>
#include <vector>

namespace vaotest
{

/// A random int16 image with a non-zero extent origin and anisotropic spacing.
inline vtkSmartPointer<vtkImageData> RandomImage(
  int nx, int ny, int nz, unsigned seed, int components = 1)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(3, 3 + nx - 1, -2, -2 + ny - 1, 5, 5 + nz - 1);
  image->SetSpacing(2.0, 1.0, 0.5);
  image->SetOrigin(-4.0, 1.5, 7.0);
  vtkNew<vtkShortArray> values;
  values->SetName("Density");
  values->SetNumberOfComponents(components);
  values->SetNumberOfTuples(image->GetNumberOfPoints());
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> uniform(-300, 900);
  for (vtkIdType i = 0; i < values->GetNumberOfValues(); ++i)
    values->SetValue(i, static_cast<short>(uniform(rng) / 50 * 50)); // ties on purpose
  image->GetPointData()->SetScalars(values);
  return image;
}

struct FilterRun
{
  vtkSmartPointer<vtkImageData> output;
  std::vector<std::string> errors;
  std::vector<std::string> warnings;
};

inline FilterRun RunFilter(
  vtkDataObject* input, const std::function<void(vtkVolumetricAmbientOcclusion*)>& configure)
{
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(filter);
  filter->SetInputData(input);
  configure(filter);
  filter->Update();
  FilterRun run{ filter->GetOutput(), catcher->Errors, catcher->Warnings };
  return run;
}

inline void ExpectRejected(vtkDataObject* input,
  const std::function<void(vtkVolumetricAmbientOcclusion*)>& configure,
  const std::string& expectedWords)
{
  // Radius 1 unless the case sets its own, so that only the named problem is present.
  const FilterRun run = RunFilter(input,
    [&](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetRadius(1);
      configure(f);
    });
  ExpectRefused(run.errors, run.output, expectedWords);
  EXPECT_EQ(run.output->GetPointData()->GetArray("AmbientOcclusion"), nullptr);
}

} // namespace vaotest
