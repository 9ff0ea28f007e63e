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
#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkNrrdReader.h"
#include "vtkPNGReader.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkXMLImageDataReader.h"
#include "vtkXMLImageDataWriter.h"

#ifdef VAO_DEMO_HAVE_FREETYPE
#include "vtkFreeTypeTools.h"
#include "vtkStdString.h"
#include "vtkTextProperty.h"
#endif

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace
{

constexpr int ExitFailure = 1;
constexpr int ExitBadInput = 2;

/// Every failure ends the program through this exception, caught once in main: the
/// functions below stay free of error plumbing.
struct DemoError
{
  int exitCode;
  std::string message;
};

[[noreturn]] void Fail(int exitCode, const std::string& message)
{
  throw DemoError{ exitCode, message };
}

//------------------------------------------------------------------------------
// The methods, in the row order of the figure (Fig. 6 of Ruiz et al. first, then this
// project's Histogram CDF, the two exact references, and the smoothed query's rows).
struct MethodInfo
{
  int id;            // vtkVolumetricAmbientOcclusion::MethodType
  const char* label; // for people: table rows and figure labels
  const char* key;   // for arrays: "<key>_R<radius>"
  int query = vtkVolumetricAmbientOcclusion::VOXEL_VALUE;
};

constexpr int Smoothed = vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE;
const std::array<MethodInfo, 8> Methods = { {
  { vtkVolumetricAmbientOcclusion::CHEBYSHEV, "Chebyshev (Penner)", "Chebyshev" },
  { vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION, "CDF Reconstruction", "CDFReconstruction" },
  { vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, "Gaussian CDF", "GaussianCDF" },
  { vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF, "Histogram CDF", "HistogramCDF" },
  { vtkVolumetricAmbientOcclusion::EXACT_BOX, "Exact Box", "ExactBox" },
  { vtkVolumetricAmbientOcclusion::EXACT_SPHERE, "Exact Sphere", "ExactSphere" },
  { vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF, "Histogram CDF, smooth q", "HistogramCDFSmoothed", Smoothed },
  { vtkVolumetricAmbientOcclusion::EXACT_BOX, "Exact Box, smooth q", "ExactBoxSmoothed", Smoothed },
} };

/// The row of method `id` with query mode `query`.
const MethodInfo& MethodWithId(int id, int query = vtkVolumetricAmbientOcclusion::VOXEL_VALUE)
{
  return *std::find_if(
    Methods.begin(), Methods.end(), [id, query](const MethodInfo& m) { return m.id == id && m.query == query; });
}

/// The oracle a row is compared with (METHODS.md): Exact Box with the same query.
const MethodInfo& ReferenceOf(const MethodInfo& method)
{
  return MethodWithId(vtkVolumetricAmbientOcclusion::EXACT_BOX, method.query);
}

std::string ArrayName(const char* key, int radius)
{
  return std::string(key) + "_R" + std::to_string(radius);
}

//------------------------------------------------------------------------------
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
    Fail(ExitBadInput, std::string(option) + " takes integers of at least " + std::to_string(minimum) + " (got '" +
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
    Fail(ExitBadInput, option + " needs " + (count < 0 ? std::string("at least one value") : std::to_string(count) + " value(s)") +
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

//------------------------------------------------------------------------------
/// Catches the error messages of a VTK object, so that a failure is reported once, in the
/// demo's words, instead of as VTK's multi-line output-window text.
class ErrorLog
{
public:
  explicit ErrorLog(vtkObject* object)
    : Object(object)
    , Tag(object->AddObserver(vtkCommand::ErrorEvent, this, &ErrorLog::OnError))
  {
  }
  ~ErrorLog() { this->Object->RemoveObserver(this->Tag); }
  ErrorLog(const ErrorLog&) = delete;
  ErrorLog& operator=(const ErrorLog&) = delete;

  /// The messages so far, or `fallback` when there were none.
  std::string Text(const std::string& fallback) const { return this->Messages.empty() ? fallback : this->Messages; }

private:
  void OnError(vtkObject*, unsigned long, void* callData)
  {
    // VTK prefixes "ClassName (0x...): "; the class name means nothing to a user.
    std::string message = static_cast<const char*>(callData);
    const std::size_t prefix = message.find("): ");
    if (prefix != std::string::npos)
    {
      message.erase(0, prefix + 3);
    }
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
    {
      message.pop_back();
    }
    this->Messages += (this->Messages.empty() ? "" : "; ") + message;
  }

  vtkObject* Object;
  unsigned long Tag;
  std::string Messages;
};

//------------------------------------------------------------------------------
// Input.
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
  Fail(ExitBadInput, "'" + path + "': unsupported file type '" + extension + "' (use .mha, .mhd, .nrrd, .nhdr or .vti).");
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
      ? " (this VTK reads .vti files with inline data only, not appended: save it inline or as .mha)"
      : "";
    Fail(ExitBadInput, "cannot read '" + path + "': " + errors.Text("the reader produced no voxels.") + hint);
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
  vtkAbstractArray* array = name.empty() ? pointData->GetScalars() : pointData->GetAbstractArray(name.c_str());
  if (!array)
  {
    std::string available;
    for (int a = 0; a < pointData->GetNumberOfArrays(); ++a)
    {
      available += std::string(available.empty() ? "" : ", ") + "'" + pointData->GetArrayName(a) + "'";
    }
    Fail(ExitBadInput, (name.empty() ? std::string("the input has no active scalars")
                                     : "the input has no point array '" + name + "'") +
        " (point arrays: " + (available.empty() ? "none" : available) + "; choose one with --scalars).");
  }
  auto* scalars = vtkDataArray::SafeDownCast(array);
  if (!scalars)
  {
    Fail(ExitBadInput, std::string("point array '") + array->GetName() + "' is not numeric.");
  }
  if (scalars->GetNumberOfComponents() != 1)
  {
    Fail(ExitBadInput, std::string("point array '") + scalars->GetName() + "' has " +
        std::to_string(scalars->GetNumberOfComponents()) +
        " components; ambient occlusion needs a scalar (one-component) array.");
  }
  return scalars;
}

//------------------------------------------------------------------------------
// Computation.
struct Computation
{
  const MethodInfo* method; // null for the Variance
  int radius;
  double seconds;
  vtkSmartPointer<vtkDataArray> values; // named as in the .vti
};

std::string Format(const char* format, double value)
{
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// One filter run: its openness array named "<key>_R<radius>", or with `variance` its
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
  vtkSmartPointer<vtkDataArray> values = filter->GetOutput()->GetPointData()->GetArray(resultName.c_str());
  if (!values)
  {
    Fail(ExitFailure, std::string(method.label) + " at R = " + std::to_string(radius) +
        " failed: " + errors.Text("no output."));
  }
  if (variance)
  {
    values->SetName(ArrayName("Variance", radius).c_str());
  }
  return { variance ? nullptr : &method, radius, seconds, values };
}

std::vector<Computation> ComputeAll(vtkImageData* image, const std::string& scalars, const std::vector<int>& radii)
{
  std::vector<Computation> results;
  const std::size_t total = radii.size() * Methods.size() + 1;
  auto report = [&](const Computation& c, const char* label) {
    std::printf("[%2zu/%zu] %-24s R = %-3d %8.3f s\n", results.size(), total, label, c.radius, c.seconds);
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
  results.push_back(
    RunFilter(image, scalars, MethodWithId(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF), radii.back(), true));
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

const Computation& Find(const std::vector<Computation>& results, const MethodInfo* method, int radius)
{
  for (const Computation& c : results)
  {
    if (c.method == method && c.radius == radius)
    {
      return c;
    }
  }
  Fail(ExitFailure, "internal error: a computation is missing.");
}

void PrintTable(const std::vector<Computation>& results)
{
  std::printf("\n%-24s %6s %9s %9s %20s %8s\n", "method", "radius", "seconds", "AO mean", "RMSE vs Exact Box",
    "bias");
  for (const Computation& c : results)
  {
    if (!c.method)
    {
      std::printf("%-24s %6d %9.3f %9s %20s %8s   (mean variance %.4g)\n", "Variance", c.radius, c.seconds, "-",
        "-", "-", Mean(c.values));
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
    std::printf("%-24s %6d %9.3f %9.3f %20s %8s\n", c.method->label, c.radius, c.seconds, Mean(c.values),
      rmse.c_str(), bias.c_str());
  }
  std::printf("\n");
}

//------------------------------------------------------------------------------
// The volume file.
vtkSmartPointer<vtkImageData> AssembleResult(
  vtkImageData* input, vtkDataArray* scalars, const std::vector<Computation>& results)
{
  auto result = vtkSmartPointer<vtkImageData>::New();
  result->CopyStructure(input);
  result->GetPointData()->SetScalars(scalars);
  for (const Computation& c : results)
  {
    result->GetPointData()->AddArray(c.values);
  }
  return result;
}

void WriteVolume(vtkImageData* image, const std::string& path)
{
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  // Inline binary: this VTK 9.2 (with the system's expat) cannot read appended data back.
  writer->SetDataModeToBinary();
  ErrorLog errors(writer);
  if (!writer->Write())
  {
    Fail(ExitFailure, "cannot write '" + path + "': " + errors.Text("the writer failed."));
  }
}

/// Names of the arrays that differ between `expected` and `actual` (empty: identical).
std::string DifferingArrays(vtkImageData* expected, vtkImageData* actual)
{
  std::string differing;
  for (int a = 0; a < expected->GetPointData()->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* want = expected->GetPointData()->GetArray(a);
    vtkDataArray* got = actual->GetPointData()->GetArray(want->GetName());
    const int components = want->GetNumberOfComponents();
    bool same = got && got->GetDataType() == want->GetDataType() &&
      got->GetNumberOfTuples() == want->GetNumberOfTuples() && got->GetNumberOfComponents() == components;
    for (vtkIdType t = 0; same && t < want->GetNumberOfTuples(); ++t)
    {
      for (int c = 0; same && c < components; ++c)
      {
        same = got->GetComponent(t, c) == want->GetComponent(t, c);
      }
    }
    if (!same)
    {
      differing += std::string(differing.empty() ? "" : ", ") + want->GetName();
    }
  }
  return differing;
}

void CheckVolumeReadBack(vtkImageData* written, const std::string& path)
{
  const auto start = std::chrono::steady_clock::now();
  vtkNew<vtkXMLImageDataReader> reader;
  reader->SetFileName(path.c_str());
  ErrorLog errors(reader);
  reader->Update();
  vtkImageData* read = reader->GetOutput();
  int writtenDims[3], readDims[3];
  written->GetDimensions(writtenDims);
  read->GetDimensions(readDims);
  if (read->GetNumberOfPoints() == 0 || !std::equal(writtenDims, writtenDims + 3, readDims))
  {
    Fail(ExitFailure, "read back of '" + path + "' failed: " + errors.Text("wrong dimensions."));
  }
  const std::string differing = DifferingArrays(written, read);
  if (!differing.empty())
  {
    Fail(ExitFailure, "read back of '" + path + "' failed: these arrays differ: " + differing + ".");
  }
  std::printf("read back: OK (%d arrays of %lld voxels, identical, checked in %.2f s)\n",
    written->GetPointData()->GetNumberOfArrays(), static_cast<long long>(written->GetNumberOfPoints()),
    SecondsSince(start));
}

//------------------------------------------------------------------------------
// The figure: a grey-level raster with row 0 at the top.
struct Raster
{
  int width = 0;
  int height = 0;
  std::vector<float> values; // row-major, top row first

  Raster(int w, int h, float fill)
    : width(w)
    , height(h)
    , values(static_cast<std::size_t>(w) * h, fill)
  {
  }
  float& At(int x, int y) { return this->values[static_cast<std::size_t>(y) * this->width + x]; }
  float At(int x, int y) const { return this->values[static_cast<std::size_t>(y) * this->width + x]; }
};

/// Which volume axes run across and up the picture for each slice axis. Head at the top
/// (z up) in sagittal and coronal views; the face at the top of an axial view.
struct SliceView
{
  int across;
  int up;
  bool upIsDecreasingIndex; // axial: image y runs front to back, and the front goes up
};

SliceView ViewFor(int sliceAxis)
{
  switch (sliceAxis)
  {
    case 0:
      return { 1, 2, false }; // sagittal: face on the left
    case 1:
      return { 0, 2, false }; // coronal
    default:
      return { 0, 1, true }; // axial
  }
}

/// The middle slice of a one-component point array, one pixel per voxel.
Raster ExtractSlice(vtkImageData* image, vtkDataArray* values, int sliceAxis)
{
  int dims[3];
  image->GetDimensions(dims);
  const SliceView view = ViewFor(sliceAxis);
  Raster slice(dims[view.across], dims[view.up], 0.0f);
  int ijk[3];
  ijk[sliceAxis] = dims[sliceAxis] / 2;
  for (int y = 0; y < slice.height; ++y)
  {
    ijk[view.up] = view.upIsDecreasingIndex ? y : slice.height - 1 - y;
    for (int x = 0; x < slice.width; ++x)
    {
      ijk[view.across] = x;
      const vtkIdType id = ijk[0] + static_cast<vtkIdType>(dims[0]) * (ijk[1] + static_cast<vtkIdType>(dims[1]) * ijk[2]);
      slice.At(x, y) = static_cast<float>(values->GetComponent(id, 0));
    }
  }
  return slice;
}

/// The two source samples around a target pixel's centre and the weight of the second.
struct LinearTap
{
  int first;
  int second;
  float weight;
};

LinearTap TapFor(int targetIndex, int targetSize, int sourceSize)
{
  const double u = std::clamp((targetIndex + 0.5) * sourceSize / targetSize - 0.5, 0.0, sourceSize - 1.0);
  const int first = static_cast<int>(u);
  return { first, std::min(first + 1, sourceSize - 1), static_cast<float>(u - first) };
}

/// Bilinear resampling to `width` x `height` pixels over the same area: square pixels for
/// anisotropic spacing, and a zoom for small volumes.
Raster Resample(const Raster& source, int width, int height)
{
  Raster target(width, height, 0.0f);
  for (int y = 0; y < height; ++y)
  {
    const LinearTap ty = TapFor(y, height, source.height);
    for (int x = 0; x < width; ++x)
    {
      const LinearTap tx = TapFor(x, width, source.width);
      const float top = source.At(tx.first, ty.first) * (1 - tx.weight) + source.At(tx.second, ty.first) * tx.weight;
      const float bottom =
        source.At(tx.first, ty.second) * (1 - tx.weight) + source.At(tx.second, ty.second) * tx.weight;
      target.At(x, y) = top * (1 - ty.weight) + bottom * ty.weight;
    }
  }
  return target;
}

/// Size in pixels of every cell: the slice's world extent in square pixels (the finer
/// in-plane spacing), zoomed by an integer factor so that small volumes give readable cells.
std::array<int, 2> CellSize(vtkImageData* image, int sliceAxis)
{
  constexpr int MinimumCellSide = 128;
  const SliceView view = ViewFor(sliceAxis);
  int dims[3];
  image->GetDimensions(dims);
  const double* spacing = image->GetSpacing();
  const double pixel = std::min(std::abs(spacing[view.across]), std::abs(spacing[view.up]));
  const double width = dims[view.across] * std::abs(spacing[view.across]) / pixel;
  const double height = dims[view.up] * std::abs(spacing[view.up]) / pixel;
  const double zoom = std::max(1.0, std::ceil(MinimumCellSide / std::max(width, height)));
  return { static_cast<int>(std::lround(width * zoom)), static_cast<int>(std::lround(height * zoom)) };
}

/// Grey levels in [0, 1] for the input: a CT window for Hounsfield data (air at -1000),
/// otherwise the data range.
struct Window
{
  double low;
  double high;
  std::string description;
};

Window InputWindow(vtkDataArray* scalars)
{
  double range[2];
  scalars->GetRange(range, 0);
  if (range[0] <= -900.0 && range[1] > 0.0)
  {
    return { -1000.0, 1000.0, "HU -1000..1000" };
  }
  return { range[0], range[1] > range[0] ? range[1] : range[0] + 1.0,
    Format("%g", range[0]) + ".." + Format("%g", range[1]) };
}

Raster ApplyWindow(Raster raster, const Window& window)
{
  for (float& v : raster.values)
  {
    v = static_cast<float>(std::clamp((v - window.low) / (window.high - window.low), 0.0, 1.0));
  }
  return raster;
}

/// Text coverage in [0, 1], row 0 at the top; empty when text rendering is unavailable.
Raster RenderLabel(const std::string& text)
{
#ifdef VAO_DEMO_HAVE_FREETYPE
  // FreeType rasterises without an OpenGL context, so labels work headless.
  vtkNew<vtkTextProperty> property;
  property->SetFontFamilyToArial();
  property->SetFontSize(15);
  property->SetColor(1.0, 1.0, 1.0);
  vtkFreeTypeTools* freeType = vtkFreeTypeTools::GetInstance();
  freeType->ScaleToPowerTwoOff(); // an image of exactly the text's size
  vtkNew<vtkImageData> image;
  int size[2] = { 0, 0 };
  if (freeType->RenderString(property, vtkStdString(text), 72, image, size) && size[0] > 0 && size[1] > 0 &&
    image->GetNumberOfScalarComponents() == 4)
  {
    const int* extent = image->GetExtent();
    Raster label(size[0], size[1], 0.0f);
    for (int y = 0; y < label.height; ++y)
    {
      for (int x = 0; x < label.width; ++x)
      {
        // VTK images have row 0 at the bottom; the alpha channel is the glyph coverage.
        const auto* rgba = static_cast<unsigned char*>(
          image->GetScalarPointer(extent[0] + x, extent[2] + label.height - 1 - y, extent[4]));
        label.At(x, y) = rgba[3] / 255.0f;
      }
    }
    return label;
  }
#else
  (void)text;
#endif
  return Raster(0, 0, 0.0f);
}

/// Pastes `cell` with its top-left corner at (left, top); the coverage of a label blends
/// white over the canvas instead.
void Paste(Raster& canvas, const Raster& cell, int left, int top, bool isLabel)
{
  for (int y = 0; y < cell.height && top + y < canvas.height; ++y)
  {
    for (int x = 0; x < cell.width && left + x < canvas.width; ++x)
    {
      float& pixel = canvas.At(left + x, top + y);
      pixel = isLabel ? pixel * (1 - cell.At(x, y)) + cell.At(x, y) : cell.At(x, y);
    }
  }
}

/// What the figure shows, cell by cell: rows[0] is the input, rows[1..] the methods.
struct FigureContent
{
  std::vector<std::string> rowLabels;
  std::vector<std::string> columnLabels;
  std::vector<std::vector<Raster>> rows; // grey levels in [0, 1]
  std::array<int, 2> cellSize;           // of every raster in rows
};

/// The labels as text coverage rasters; empty when any of them cannot be rendered.
struct Labels
{
  std::vector<Raster> rows;
  std::vector<Raster> columns;
  bool Empty() const { return this->rows.empty(); }
};

Labels RenderLabels(const FigureContent& content)
{
  Labels labels;
  for (const auto& text : content.rowLabels)
  {
    labels.rows.push_back(RenderLabel(text));
  }
  for (const auto& text : content.columnLabels)
  {
    labels.columns.push_back(RenderLabel(text));
  }
  auto rendered = [](const std::vector<Raster>& r) {
    return std::all_of(r.begin(), r.end(), [](const Raster& label) { return label.width > 0; });
  };
  return rendered(labels.rows) && rendered(labels.columns) ? labels : Labels{};
}

/// The grid: row labels on the left, the input row, column labels, then one row per
/// method; grey separators between cells.
Raster ComposeFigure(const FigureContent& content, const Labels& labels)
{
  const std::array<int, 2>& cellSize = content.cellSize;
  constexpr int Margin = 8, Separator = 2;
  constexpr float Background = 0.0f, SeparatorGrey = 0.5f;
  int labelWidth = 0, headerHeight = Margin;
  for (const Raster& label : labels.rows)
  {
    labelWidth = std::max(labelWidth, label.width + Margin);
  }
  for (const Raster& label : labels.columns)
  {
    headerHeight = std::max(headerHeight, label.height + 2 * Margin);
  }
  const int columns = static_cast<int>(content.columnLabels.size());
  const int methodRows = static_cast<int>(content.rows.size()) - 1;
  const int gridLeft = Margin + labelWidth, pitchX = cellSize[0] + Separator, pitchY = cellSize[1] + Separator;
  const int methodsTop = Margin + cellSize[1] + headerHeight;
  Raster canvas(gridLeft + columns * pitchX - Separator + Margin, methodsTop + methodRows * pitchY - Separator + Margin,
    Background);

  // The method grid on a separator-grey ground: the gaps between cells stay grey.
  Paste(canvas, Raster(columns * pitchX - Separator, methodRows * pitchY - Separator, SeparatorGrey), gridLeft,
    methodsTop, false);
  for (std::size_t row = 0; row < content.rows.size(); ++row)
  {
    const int top = row == 0 ? Margin : methodsTop + static_cast<int>(row - 1) * pitchY;
    for (std::size_t column = 0; column < content.rows[row].size(); ++column)
    {
      Paste(canvas, content.rows[row][column], gridLeft + static_cast<int>(column) * pitchX, top, false);
    }
    if (!labels.Empty())
    {
      Paste(canvas, labels.rows[row], Margin, top + (cellSize[1] - labels.rows[row].height) / 2, true);
    }
  }
  for (std::size_t column = 0; column < labels.columns.size(); ++column)
  {
    const Raster& label = labels.columns[column];
    Paste(canvas, label, gridLeft + static_cast<int>(column) * pitchX + (cellSize[0] - label.width) / 2,
      Margin + cellSize[1] + (headerHeight - label.height) / 2, true);
  }
  return canvas;
}

FigureContent BuildFigureContent(vtkImageData* image, vtkDataArray* scalars, const std::vector<Computation>& results,
  const std::vector<int>& radii, int sliceAxis)
{
  FigureContent content;
  content.cellSize = CellSize(image, sliceAxis);
  auto cell = [&](vtkDataArray* values) {
    return Resample(ExtractSlice(image, values, sliceAxis), content.cellSize[0], content.cellSize[1]);
  };
  const Window window = InputWindow(scalars);
  content.rowLabels.push_back("Input (" + window.description + ")");
  content.rows.push_back({ ApplyWindow(cell(scalars), window) });
  for (int radius : radii)
  {
    content.columnLabels.push_back("R = " + std::to_string(radius));
  }
  for (const MethodInfo& method : Methods)
  {
    content.rowLabels.emplace_back(method.label);
    content.rows.emplace_back();
    for (int radius : radii)
    {
      content.rows.back().push_back(cell(Find(results, &method, radius).values)); // AO is in [0, 1] already
    }
  }
  return content;
}

/// Without text rendering the layout goes to stdout and to a .txt beside the PNG.
void WriteLegend(const FigureContent& content, const std::string& pngPath)
{
  std::string legend = "Layout of " + pngPath + " (no text rendering available):\n  row 1, column 1: " +
    content.rowLabels[0] + "\n  columns, left to right:";
  for (const auto& label : content.columnLabels)
  {
    legend += " " + label + ";";
  }
  legend += "\n  rows 2.., top to bottom:";
  for (std::size_t row = 1; row < content.rowLabels.size(); ++row)
  {
    legend += " " + content.rowLabels[row] + ";";
  }
  legend += "\n  grey: 0 black = occluded, 1 white = open\n";
  std::cout << legend;
  const std::string path = std::filesystem::path(pngPath).replace_extension(".txt").string();
  std::ofstream(path) << legend;
}

void WritePng(const Raster& canvas, const std::string& path)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(canvas.width, canvas.height, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* pixels = static_cast<unsigned char*>(image->GetScalarPointer());
  for (int y = 0; y < canvas.height; ++y)
  {
    for (int x = 0; x < canvas.width; ++x)
    {
      // VTK images (and so the PNG writer) have row 0 at the bottom.
      pixels[static_cast<std::size_t>(canvas.height - 1 - y) * canvas.width + x] =
        static_cast<unsigned char>(std::lround(255.0f * std::clamp(canvas.At(x, y), 0.0f, 1.0f)));
    }
  }
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  ErrorLog errors(writer);
  writer->Write();
  if (writer->GetErrorCode() != 0)
  {
    Fail(ExitFailure, "cannot write '" + path + "': " + errors.Text("the PNG writer failed."));
  }
}

void CheckPngReadBack(const Raster& canvas, const std::string& path)
{
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(path.c_str());
  ErrorLog errors(reader);
  reader->Update();
  int dims[3];
  reader->GetOutput()->GetDimensions(dims);
  if (dims[0] != canvas.width || dims[1] != canvas.height)
  {
    Fail(ExitFailure, "read back of '" + path + "' failed: " + errors.Text("wrong dimensions."));
  }
  std::printf("PNG read back: OK (%d x %d pixels in %s)\n", dims[0], dims[1], path.c_str());
}

void WriteFigure(vtkImageData* image, vtkDataArray* scalars, const std::vector<Computation>& results,
  const Options& options, const std::string& path)
{
  const FigureContent content = BuildFigureContent(image, scalars, results, options.radii, options.sliceAxis);
  const Labels labels = RenderLabels(content);
  const Raster canvas = ComposeFigure(content, labels);
  if (labels.Empty())
  {
    WriteLegend(content, path);
  }
  WritePng(canvas, path);
  CheckPngReadBack(canvas, path);
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
  std::printf("input: %s, %d x %d x %d voxels, spacing %g x %g x %g, array '%s' (%s), %s in %.2f s\n",
    options.input.empty() ? "generated phantom" : options.input.c_str(), dims[0], dims[1], dims[2], spacing[0],
    spacing[1], spacing[2], scalars->GetName(), scalars->GetDataTypeAsString(),
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
  const std::string volumePath = (std::filesystem::path(options.outputDir) / "ambient_occlusion.vti").string();
  const vtkSmartPointer<vtkImageData> result = AssembleResult(image, scalars, results);
  start = std::chrono::steady_clock::now();
  WriteVolume(result, volumePath);
  std::printf("wrote %s in %.2f s\n", volumePath.c_str(), SecondsSince(start));
  CheckVolumeReadBack(result, volumePath);
  WriteFigure(image, scalars, results, options,
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
