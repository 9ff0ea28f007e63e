// vao-demo, the main job: volumetric ambient occlusion with every method of Ruiz et al.
// 2010 on one volume, compared with the Exact Box reference, saved and checked.
//
// Usage: vao-demo [INPUT] [--output DIR] [--dimensions NX NY NZ] [--radii R1 R2 ...]
//                 [--scalars NAME] [--slice-axis x|y|z]
//
//  INPUT          .mha/.mhd (MetaImage), .nrrd/.nhdr (NRRD) or .vti (XML image data; this
//                 VTK 9.2 reads inline data only, not appended); without it, the generated
//                 CT-like head phantom (vtkAmbientOcclusionPhantom).
//  --output       directory for the results (default ./vao-output, created if missing).
//  --dimensions   size of the generated phantom (default 128 128 128).
//  --radii        kernel radii in voxels, one or more (default 5 10).
//  --scalars      point array to process (default: the active scalars).
//  --slice-axis   axis normal to the figure's slice (default x: sagittal).
//
// Writes DIR/ambient_occlusion.vti (the input array, one float32 array per method and
// radius, e.g. "GaussianCDF_R5", and "Variance_R<largest>") and
// DIR/ambient_occlusion_slices.png (Fig. 6 of Ruiz et al. extended to every method), and
// reads both back. Exit codes: 0 success, 1 computation or I/O failure, 2 bad arguments or
// input.
#include "DemoCommon.h"
#include "DemoFigure.h"
#include "DemoVolumeFile.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkNrrdReader.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkXMLImageDataReader.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace
{

using namespace vaodemo;

// Command line.
struct Options
{
  std::string input; // empty: the generated phantom
  std::string outputDir = "vao-output";
  std::array<int, 3> dimensions = { 128, 128, 128 };
  bool dimensionsGiven = false;
  std::vector<int> radii = { 5, 10 };
  std::string scalars; // empty: the active scalars
  int sliceAxis = 0;
};

const char* const Usage =
  "usage: vao-demo [INPUT.mha|.mhd|.nrrd|.nhdr|.vti] [--output DIR] [--dimensions NX NY NZ]\n"
  "                [--radii R1 R2 ...] [--scalars NAME] [--slice-axis x|y|z]\n";

int ParseInt(const std::string& text, const char* option, int minimum)
{
  std::size_t used = 0;
  int value = 0;
  try
  {
    value = std::stoi(text, &used);
  }
  catch (const std::exception&)
  {
    used = 0;
  }
  if (used != text.size() || value < minimum)
  {
    Fail(ExitBadInput,
      std::string(option) + " takes integers of at least " + std::to_string(minimum) + " (got '" +
        text + "').\n" + Usage);
  }
  return value;
}

/// The values after option argv[i]: `count` of them, or (count < 0) all up to the next option.
std::vector<std::string> OptionValues(int argc, char** argv, int& i, int count)
{
  const std::string option = argv[i];
  std::vector<std::string> values;
  while (i + 1 < argc && (count < 0 || static_cast<int>(values.size()) < count) &&
    std::string(argv[i + 1]).rfind("--", 0) != 0)
  {
    values.emplace_back(argv[++i]);
  }
  if (values.empty() || (count >= 0 && static_cast<int>(values.size()) != count))
  {
    Fail(ExitBadInput,
      option + " needs " +
        (count < 0 ? std::string("at least one value") : std::to_string(count) + " value(s)") +
        ".\n" + Usage);
  }
  return values;
}

Options ParseArguments(int argc, char** argv)
{
  Options options;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h")
    {
      std::cout << Usage;
      std::exit(0);
    }
    else if (arg == "--output")
    {
      options.outputDir = OptionValues(argc, argv, i, 1)[0];
    }
    else if (arg == "--dimensions")
    {
      const auto values = OptionValues(argc, argv, i, 3);
      for (int a = 0; a < 3; ++a)
      {
        options.dimensions[a] = ParseInt(values[a], "--dimensions", 2); // a volume, not a slice
      }
      options.dimensionsGiven = true;
    }
    else if (arg == "--radii")
    {
      options.radii.clear();
      for (const auto& value : OptionValues(argc, argv, i, -1))
      {
        options.radii.push_back(ParseInt(value, "--radii", 1));
      }
    }
    else if (arg == "--scalars")
    {
      options.scalars = OptionValues(argc, argv, i, 1)[0];
    }
    else if (arg == "--slice-axis")
    {
      const std::string axis = OptionValues(argc, argv, i, 1)[0];
      if (axis != "x" && axis != "y" && axis != "z")
      {
        Fail(ExitBadInput, "--slice-axis must be x, y or z (got '" + axis + "').\n" + Usage);
      }
      options.sliceAxis = axis[0] - 'x';
    }
    else if (arg.rfind("--", 0) == 0 || !options.input.empty())
    {
      Fail(ExitBadInput, "unexpected argument '" + arg + "'.\n" + Usage);
    }
    else
    {
      options.input = arg;
    }
  }
  if (options.dimensionsGiven && !options.input.empty())
  {
    Fail(ExitBadInput, "--dimensions sizes the generated phantom; it cannot resize INPUT.");
  }
  // Ascending radii: the last is the largest (the Variance's radius, the figure's last column).
  std::sort(options.radii.begin(), options.radii.end());
  options.radii.erase(std::unique(options.radii.begin(), options.radii.end()), options.radii.end());
  return options;
}
std::string LowerCaseExtension(const std::string& path)
{
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// A reader of type Reader for `path`, after checking that it recognises the file.
template <class Reader>
vtkSmartPointer<vtkAlgorithm> CheckedReader(const std::string& path)
{
  auto reader = vtkSmartPointer<Reader>::New();
  if (!reader->CanReadFile(path.c_str()))
  {
    Fail(ExitBadInput, "'" + path + "' is not a readable " + LowerCaseExtension(path) + " file.");
  }
  reader->SetFileName(path.c_str());
  return reader;
}

vtkSmartPointer<vtkAlgorithm> OpenReader(const std::string& path)
{
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error) || !std::ifstream(path))
  {
    Fail(ExitBadInput, "cannot open '" + path + "': no such readable file.");
  }
  const std::string extension = LowerCaseExtension(path);
  if (extension == ".mha" || extension == ".mhd")
  {
    return CheckedReader<vtkMetaImageReader>(path);
  }
  if (extension == ".nrrd" || extension == ".nhdr")
  {
    return CheckedReader<vtkNrrdReader>(path);
  }
  if (extension == ".vti")
  {
    return CheckedReader<vtkXMLImageDataReader>(path);
  }
  Fail(ExitBadInput,
    "'" + path + "': unsupported file type '" + extension +
      "' (use .mha, .mhd, .nrrd, .nhdr or .vti).");
}

vtkSmartPointer<vtkImageData> ReadVolume(const std::string& path)
{
  vtkSmartPointer<vtkAlgorithm> reader = OpenReader(path);
  ErrorLog errors(reader);
  reader->Update();
  vtkSmartPointer<vtkImageData> image = vtkImageData::SafeDownCast(reader->GetOutputDataObject(0));
  if (!image || image->GetNumberOfPoints() == 0)
  {
    // The usual cause here: the expat of this machine breaks VTK 9.2's appended-data parsing.
    const std::string hint = LowerCaseExtension(path) == ".vti"
      ? " (this VTK reads .vti files with inline data only, not appended: save it inline or as "
        ".mha)"
      : "";
    Fail(ExitBadInput,
      "cannot read '" + path + "': " + errors.Text("the reader produced no voxels.") + hint);
  }
  return image;
}

vtkSmartPointer<vtkImageData> GeneratePhantom(const std::array<int, 3>& dimensions)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(dimensions.data());
  ErrorLog errors(phantom);
  phantom->Update();
  vtkSmartPointer<vtkImageData> image = phantom->GetOutput();
  if (image->GetNumberOfPoints() == 0)
  {
    Fail(ExitBadInput, "cannot generate the phantom: " + errors.Text("no voxels."));
  }
  return image;
}

/// The one-component numeric point array to process (by name, or the active scalars).
vtkDataArray* SelectScalars(vtkImageData* image, const std::string& name)
{
  vtkPointData* pointData = image->GetPointData();
  vtkAbstractArray* array =
    name.empty() ? pointData->GetScalars() : pointData->GetAbstractArray(name.c_str());
  if (!array)
  {
    std::string available;
    for (int a = 0; a < pointData->GetNumberOfArrays(); ++a)
    {
      available +=
        std::string(available.empty() ? "" : ", ") + "'" + pointData->GetArrayName(a) + "'";
    }
    Fail(ExitBadInput,
      (name.empty() ? std::string("the input has no active scalars")
                    : "the input has no point array '" + name + "'") +
        " (point arrays: " + (available.empty() ? "none" : available) +
        "; choose one with --scalars).");
  }
  auto* scalars = vtkDataArray::SafeDownCast(array);
  if (!scalars)
  {
    Fail(ExitBadInput, std::string("point array '") + array->GetName() + "' is not numeric.");
  }
  if (scalars->GetNumberOfComponents() != 1)
  {
    Fail(ExitBadInput,
      std::string("point array '") + scalars->GetName() + "' has " +
        std::to_string(scalars->GetNumberOfComponents()) +
        " components; ambient occlusion needs a scalar (one-component) array.");
  }
  return scalars;
}

/// Variance array renamed "Variance_R<radius>".
Computation RunFilter(vtkImageData* image, const std::string& scalars, const MethodInfo& method,
  int radius, bool variance)
{
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputData(image);
  filter->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, scalars.c_str());
  filter->SetMethod(method.id);
  filter->SetQueryMode(method.query);
  filter->SetRadius(radius);
  filter->SetOutputArrayName(ArrayName(method.key, radius).c_str());
  filter->SetComputeVariance(variance);
  ErrorLog errors(filter);
  const auto start = std::chrono::steady_clock::now();
  filter->Update();
  const double seconds = SecondsSince(start);
  const std::string resultName = variance ? "Variance" : ArrayName(method.key, radius);
  vtkSmartPointer<vtkDataArray> values =
    filter->GetOutput()->GetPointData()->GetArray(resultName.c_str());
  if (!values)
  {
    Fail(ExitFailure,
      std::string(method.label) + " at R = " + std::to_string(radius) +
        " failed: " + errors.Text("no output."));
  }
  if (variance)
  {
    values->SetName(ArrayName("Variance", radius).c_str());
  }
  return { variance ? nullptr : &method, radius, seconds, values };
}

std::vector<Computation> ComputeAll(
  vtkImageData* image, const std::string& scalars, const std::vector<int>& radii)
{
  std::vector<Computation> results;
  const std::size_t total = radii.size() * Methods.size() + 1;
  auto report = [&](const Computation& c, const char* label)
  {
    std::printf(
      "[%2zu/%zu] %-24s R = %-3d %8.3f s\n", results.size(), total, label, c.radius, c.seconds);
    std::fflush(stdout);
  };
  for (int radius : radii)
  {
    for (const MethodInfo& method : Methods)
    {
      results.push_back(RunFilter(image, scalars, method, radius, false));
      report(results.back(), method.label);
    }
  }
  // The variance comes with every estimator's box statistics; Gaussian CDF is the cheapest
  // run that yields it (its openness array is dropped).
  results.push_back(RunFilter(
    image, scalars, MethodWithId(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF), radii.back(), true));
  report(results.back(), "Variance");
  return results;
}

//------------------------------------------------------------------------------
// Statistics and the table.
double Mean(vtkDataArray* values)
{
  double sum = 0.0;
  for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
  {
    sum += values->GetComponent(i, 0);
  }
  return sum / std::max<vtkIdType>(1, values->GetNumberOfTuples());
}

struct Deviation
{
  double rmse;
  double bias; // mean of (estimate - reference): negative = darker than the reference
};

Deviation Compare(vtkDataArray* estimate, vtkDataArray* reference)
{
  double sum = 0.0, sumSquares = 0.0;
  const vtkIdType n = estimate->GetNumberOfTuples();
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double d = estimate->GetComponent(i, 0) - reference->GetComponent(i, 0);
    sum += d;
    sumSquares += d * d;
  }
  return { std::sqrt(sumSquares / std::max<vtkIdType>(1, n)), sum / std::max<vtkIdType>(1, n) };
}

void PrintTable(const std::vector<Computation>& results)
{
  std::printf("\n%-24s %6s %9s %9s %20s %8s\n", "method", "radius", "seconds", "AO mean",
    "RMSE vs Exact Box", "bias");
  for (const Computation& c : results)
  {
    if (!c.method)
    {
      std::printf("%-24s %6d %9.3f %9s %20s %8s   (mean variance %.4g)\n", "Variance", c.radius,
        c.seconds, "-", "-", "-", Mean(c.values));
      continue;
    }
    std::string rmse = "(reference)", bias;
    const MethodInfo& reference = ReferenceOf(*c.method);
    if (c.method != &reference)
    {
      const Deviation d = Compare(c.values, Find(results, &reference, c.radius).values);
      rmse = Format("%.3f", d.rmse);
      bias = Format("%+.3f", d.bias);
    }
    std::printf("%-24s %6d %9.3f %9.3f %20s %8s\n", c.method->label, c.radius, c.seconds,
      Mean(c.values), rmse.c_str(), bias.c_str());
  }
  std::printf("\n");
}

//------------------------------------------------------------------------------
void Run(const Options& options)
{
  auto start = std::chrono::steady_clock::now();
  vtkSmartPointer<vtkImageData> image =
    options.input.empty() ? GeneratePhantom(options.dimensions) : ReadVolume(options.input);
  vtkDataArray* scalars = SelectScalars(image, options.scalars);
  int dims[3];
  image->GetDimensions(dims);
  const double* spacing = image->GetSpacing();
  std::printf(
    "input: %s, %d x %d x %d voxels, spacing %g x %g x %g, array '%s' (%s), %s in %.2f s\n",
    options.input.empty() ? "generated phantom" : options.input.c_str(), dims[0], dims[1], dims[2],
    spacing[0], spacing[1], spacing[2], scalars->GetName(), scalars->GetDataTypeAsString(),
    options.input.empty() ? "generated" : "read", SecondsSince(start));
  std::fflush(stdout);

  // Before the computations: a bad --output must not cost their time.
  std::error_code error;
  std::filesystem::create_directories(options.outputDir, error);
  if (error)
  {
    Fail(ExitFailure, "cannot create '" + options.outputDir + "': " + error.message() + ".");
  }

  const std::vector<Computation> results = ComputeAll(image, scalars->GetName(), options.radii);
  PrintTable(results);
  const std::string volumePath =
    (std::filesystem::path(options.outputDir) / "ambient_occlusion.vti").string();
  const vtkSmartPointer<vtkImageData> result = AssembleResult(image, scalars, results);
  start = std::chrono::steady_clock::now();
  WriteVolume(result, volumePath);
  std::printf("wrote %s in %.2f s\n", volumePath.c_str(), SecondsSince(start));
  CheckVolumeReadBack(result, volumePath);
  WriteFigure(image, scalars, results, options.radii, options.sliceAxis,
    (std::filesystem::path(options.outputDir) / "ambient_occlusion_slices.png").string());
}

} // namespace

int main(int argc, char* argv[])
{
  try
  {
    Run(ParseArguments(argc, argv));
  }
  catch (const DemoError& error)
  {
    std::cerr << "vao-demo: " << error.message << "\n";
    return error.exitCode;
  }
  return 0;
}
