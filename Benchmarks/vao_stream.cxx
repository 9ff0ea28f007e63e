// vao_stream: Volumetric Ambient Occlusion of a volume larger than memory, in pieces, through
// VTK's streaming pipeline: a raw reader that reads only the requested sub-extent ->
// vtkVolumetricAmbientOcclusion (which asks for its piece grown by the radius) -> this
// program, which asks for one z-slab at a time and appends it to the output file.
//
//   vao_stream generate OUT.mhd NX NY NZ
//       the project's head phantom (int16), generated and written slab by slab
//   vao_stream ao IN.mhd OUT.mhd [--pieces N] [--radius R] [--method
//   gaussian|cdf|chebyshev|histogram]
//       float32 AmbientOcclusion of an uncompressed MetaImage (.mhd + raw data file);
//       histogram: Histogram CDF, whose thresholds are first read from the slabs
//   vao_stream check IN.mhd AO.mhd [--radius R] [--method ...]
//       reads both back with vtkMetaImageReader and compares AO.mhd with the filter run on
//       the whole input in memory (for volumes that fit)
//
// Both print the slabs, the most slices the reader held at once and the peak resident
// memory (VmHWM). Exit status: 0 done, 1 failed, 2 bad arguments or files.
#include "ProcessMemory.h"
#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkImageReader.h>
#include <vtkInformation.h>
#include <vtkMetaImageReader.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkType.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace
{

/// What the streaming needs from a MetaImage header.
struct Header
{
  int dims[3] = { 0, 0, 0 };
  double spacing[3] = { 1, 1, 1 };
  double origin[3] = { 0, 0, 0 };
  int type = VTK_VOID;  // VTK scalar type
  std::string dataFile; // absolute or relative to the header's folder
  bool bigEndian = false;
  long headerSize = 0;
};

const std::map<std::string, int> kMetTypes = { { "MET_CHAR", VTK_SIGNED_CHAR },
  { "MET_UCHAR", VTK_UNSIGNED_CHAR }, { "MET_SHORT", VTK_SHORT },
  { "MET_USHORT", VTK_UNSIGNED_SHORT }, { "MET_INT", VTK_INT }, { "MET_UINT", VTK_UNSIGNED_INT },
  { "MET_FLOAT", VTK_FLOAT }, { "MET_DOUBLE", VTK_DOUBLE } };

std::string Folder(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

std::string BaseName(const std::string& path)
{
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

/// Reads an uncompressed, single-channel 3-D MetaImage header; false with a reason.
bool ReadHeader(const std::string& path, Header& h, std::string& why)
{
  std::ifstream in(path);
  if (!in)
  {
    why = "cannot open " + path;
    return false;
  }
  std::string line;
  while (std::getline(in, line))
  {
    const auto eq = line.find('=');
    if (eq == std::string::npos)
      continue;
    std::string key = line.substr(0, eq);
    key.erase(key.find_last_not_of(" \t") + 1);
    std::istringstream value(line.substr(eq + 1));
    if (key == "NDims")
    {
      int n = 0;
      value >> n;
      if (n != 3)
      {
        why = path + ": NDims must be 3";
        return false;
      }
    }
    else if (key == "DimSize")
      value >> h.dims[0] >> h.dims[1] >> h.dims[2];
    else if (key == "ElementSpacing")
      value >> h.spacing[0] >> h.spacing[1] >> h.spacing[2];
    else if (key == "Offset" || key == "Origin" || key == "Position")
      value >> h.origin[0] >> h.origin[1] >> h.origin[2];
    else if (key == "HeaderSize")
      value >> h.headerSize;
    else if (key == "ElementType")
    {
      std::string name;
      value >> name;
      const auto found = kMetTypes.find(name);
      h.type = found == kMetTypes.end() ? VTK_VOID : found->second;
    }
    else if (key == "BinaryDataByteOrderMSB" || key == "ElementByteOrderMSB")
    {
      std::string flag;
      value >> flag;
      h.bigEndian = flag == "True" || flag == "true";
    }
    else if (key == "CompressedData")
    {
      std::string flag;
      value >> flag;
      if (flag == "True" || flag == "true")
      {
        why = path + ": compressed data cannot be read in pieces";
        return false;
      }
    }
    else if (key == "ElementNumberOfChannels")
    {
      int channels = 1;
      value >> channels;
      if (channels != 1)
      {
        why = path + ": only single-channel data";
        return false;
      }
    }
    else if (key == "ElementDataFile")
    {
      value >> h.dataFile;
      if (h.dataFile == "LOCAL" || h.dataFile == "LIST")
      {
        why = path + ": the data must be in a separate raw file (ElementDataFile = NAME.raw)";
        return false;
      }
      if (h.dataFile[0] != '/')
        h.dataFile = Folder(path) + h.dataFile;
    }
  }
  if (h.dims[0] < 1 || h.dims[1] < 1 || h.dims[2] < 1 || h.type == VTK_VOID || h.dataFile.empty())
  {
    why = path + ": DimSize, a supported ElementType and ElementDataFile are required";
    return false;
  }
  return true;
}

bool WriteHeader(const std::string& path, const Header& h, const char* metType)
{
  std::ofstream out(path);
  out << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
      << "CompressedData = False\nOffset = " << h.origin[0] << " " << h.origin[1] << " "
      << h.origin[2] << "\nElementSpacing = " << h.spacing[0] << " " << h.spacing[1] << " "
      << h.spacing[2] << "\nDimSize = " << h.dims[0] << " " << h.dims[1] << " " << h.dims[2]
      << "\nElementType = " << metType << "\nElementDataFile = " << BaseName(h.dataFile) << "\n";
  return static_cast<bool>(out);
}

/// Slab p of n along z, as an extent.
void Slab(const int dims[3], int p, int n, int ext[6])
{
  ext[0] = 0, ext[1] = dims[0] - 1, ext[2] = 0, ext[3] = dims[1] - 1;
  ext[4] = static_cast<int>(static_cast<long long>(dims[2]) * p / n);
  ext[5] = static_cast<int>(static_cast<long long>(dims[2]) * (p + 1) / n) - 1;
}

/// Appends the point array of `image` (the requested slab) to the raw file.
bool AppendSlab(std::ofstream& out, vtkDataArray* array)
{
  const auto bytes = array->GetNumberOfValues() * array->GetDataTypeSize();
  out.write(static_cast<const char*>(array->GetVoidPointer(0)), bytes);
  return static_cast<bool>(out);
}

double Seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void PrintMemory()
{
  std::printf("peak resident memory: %.1f MB\n", vao_bench::StatusBytes("VmHWM:") / 1048576.0);
}

int Generate(const std::string& path, const int dims[3])
{
  const auto start = std::chrono::steady_clock::now();
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(dims[0], dims[1], dims[2]);
  phantom->UpdateInformation();
  Header h;
  std::copy(dims, dims + 3, h.dims);
  vtkInformation* info = phantom->GetOutputInformation(0);
  info->Get(vtkDataObject::SPACING(), h.spacing);
  info->Get(vtkDataObject::ORIGIN(), h.origin);
  h.dataFile = path.substr(0, path.find_last_of('.')) + ".raw";
  std::ofstream raw(h.dataFile, std::ios::binary);
  if (!raw || !WriteHeader(path, h, "MET_SHORT"))
  {
    std::fprintf(stderr, "vao_stream: cannot write %s\n", path.c_str());
    return 2;
  }
  // Slabs of about 64 MB of int16.
  const long long plane = static_cast<long long>(dims[0]) * dims[1];
  const int pieces = static_cast<int>(std::max<long long>(1, plane * dims[2] * 2 / (64LL << 20)));
  for (int p = 0; p < pieces; ++p)
  {
    int ext[6];
    Slab(dims, p, pieces, ext);
    phantom->UpdateExtent(ext);
    if (!AppendSlab(raw, phantom->GetOutput()->GetPointData()->GetScalars()))
    {
      std::fprintf(stderr, "vao_stream: writing %s failed\n", h.dataFile.c_str());
      return 1;
    }
  }
  std::printf("generated %s: %d x %d x %d int16 (%.0f MB) in %d slabs, %.1f s\n", path.c_str(),
    dims[0], dims[1], dims[2], plane * dims[2] * 2 / 1048576.0, pieces, Seconds(start));
  PrintMemory();
  return 0;
}

int AmbientOcclusion(
  const std::string& inPath, const std::string& outPath, int pieces, double radius, int method)
{
  const auto start = std::chrono::steady_clock::now();
  Header in;
  std::string why;
  if (!ReadHeader(inPath, in, why))
  {
    std::fprintf(stderr, "vao_stream: %s\n", why.c_str());
    return 2;
  }
  vtkNew<vtkImageReader> reader;
  reader->SetFileName(in.dataFile.c_str());
  reader->SetDataScalarType(in.type);
  reader->SetNumberOfScalarComponents(1);
  reader->SetFileDimensionality(3);
  reader->SetDataExtent(0, in.dims[0] - 1, 0, in.dims[1] - 1, 0, in.dims[2] - 1);
  reader->SetDataSpacing(in.spacing);
  reader->SetDataOrigin(in.origin);
  reader->SetHeaderSize(static_cast<unsigned long>(in.headerSize));
  reader->SetFileLowerLeft(1); // rows in file order (MetaImage), not flipped
  in.bigEndian ? reader->SetDataByteOrderToBigEndian() : reader->SetDataByteOrderToLittleEndian();
  reader->SetScalarArrayName("Scalars");

  // The most slices the reader held at once, whatever asked for them.
  int mostSlicesRead = 0;
  vtkNew<vtkCallbackCommand> watch;
  watch->SetClientData(&mostSlicesRead);
  watch->SetCallback(
    [](vtkObject* caller, unsigned long, void* most, void*)
    {
      const int* read = static_cast<vtkImageReader*>(caller)->GetOutput()->GetExtent();
      int& slices = *static_cast<int*>(most);
      slices = std::max(slices, read[5] - read[4] + 1);
    });
  reader->AddObserver(vtkCommand::EndEvent, watch);

  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputConnection(reader->GetOutputPort());
  filter->SetMethod(method);
  filter->SetRadius(radius);
  pieces = std::max(1, std::min(pieces, in.dims[2]));
  if (method == vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF)
  {
    // The thresholds of the whole volume, read slab by slab (twice: range, histogram).
    vtkSmartPointer<vtkDoubleArray> thresholds = filter->ComputeHistogramThresholds(pieces);
    if (!thresholds)
    {
      std::fprintf(
        stderr, "vao_stream: the thresholds of %s could not be computed\n", inPath.c_str());
      return 1;
    }
    filter->SetHistogramThresholds(thresholds);
    std::printf("thresholds: %lld, from %g to %g, read in %d slabs\n",
      static_cast<long long>(thresholds->GetNumberOfTuples()), thresholds->GetValue(0),
      thresholds->GetValue(thresholds->GetNumberOfTuples() - 1), pieces);
  }

  Header out = in;
  out.dataFile = outPath.substr(0, outPath.find_last_of('.')) + ".raw";
  std::ofstream raw(out.dataFile, std::ios::binary);
  if (!raw || !WriteHeader(outPath, out, "MET_FLOAT"))
  {
    std::fprintf(stderr, "vao_stream: cannot write %s\n", outPath.c_str());
    return 2;
  }
  for (int p = 0; p < pieces; ++p)
  {
    int ext[6];
    Slab(in.dims, p, pieces, ext);
    filter->UpdateExtent(ext);
    vtkImageData* slab = filter->GetOutput();
    const int* got = slab->GetExtent();
    vtkDataArray* ao = slab->GetPointData()->GetArray("AmbientOcclusion");
    if (!ao || !std::equal(ext, ext + 6, got))
    {
      std::fprintf(stderr, "vao_stream: slab %d (z %d..%d) failed\n", p, ext[4], ext[5]);
      return 1;
    }
    if (!AppendSlab(raw, ao))
    {
      std::fprintf(stderr, "vao_stream: writing %s failed\n", out.dataFile.c_str());
      return 1;
    }
  }
  const double mb = static_cast<double>(in.dims[0]) * in.dims[1] * in.dims[2] *
    reader->GetOutput()->GetPointData()->GetScalars()->GetDataTypeSize() / 1048576.0;
  std::printf("streamed %s (%d x %d x %d, %.0f MB) -> %s in %d pieces, R = %g: %.1f s\n",
    inPath.c_str(), in.dims[0], in.dims[1], in.dims[2], mb, outPath.c_str(), pieces, radius,
    Seconds(start));
  std::printf("most slices read at once: %d of %d\n", mostSlicesRead, in.dims[2]);
  PrintMemory();
  return 0;
}

int Usage()
{
  std::fprintf(stderr,
    "usage: vao_stream generate OUT.mhd NX NY NZ\n"
    "       vao_stream ao IN.mhd OUT.mhd [--pieces N] [--radius R] [--method "
    "gaussian|cdf|chebyshev|histogram]\n"
    "       vao_stream check IN.mhd AO.mhd [--radius R] [--method "
    "gaussian|cdf|chebyshev|histogram]\n");
  return 2;
}

/// Reads a whole MetaImage with VTK's own reader (nullptr with a message if it cannot).
vtkSmartPointer<vtkImageData> ReadWhole(const std::string& path)
{
  vtkNew<vtkMetaImageReader> reader;
  if (!reader->CanReadFile(path.c_str()))
  {
    std::fprintf(stderr, "vao_stream: cannot open %s\n", path.c_str());
    return nullptr;
  }
  reader->SetFileName(path.c_str());
  reader->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->ShallowCopy(reader->GetOutput());
  return image;
}

/// Reads both files back with vtkMetaImageReader (an independent reader: header, type and
/// orientation), computes the AO of the whole input in memory and compares.
int Check(const std::string& inPath, const std::string& aoPath, double radius, int method)
{
  auto input = ReadWhole(inPath), streamed = ReadWhole(aoPath);
  if (!input || !streamed)
    return 2;
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputData(input);
  filter->SetMethod(method);
  filter->SetRadius(radius);
  filter->Update();
  vtkDataArray* want = filter->GetOutput()->GetPointData()->GetArray("AmbientOcclusion");
  vtkDataArray* got = streamed->GetPointData()->GetScalars();
  if (!want || !got || want->GetNumberOfTuples() != got->GetNumberOfTuples() ||
    !std::equal(input->GetDimensions(), input->GetDimensions() + 3, streamed->GetDimensions()))
  {
    std::fprintf(
      stderr, "vao_stream: %s does not match %s in size\n", aoPath.c_str(), inPath.c_str());
    return 1;
  }
  double worst = 0.0;
  for (vtkIdType i = 0; i < want->GetNumberOfTuples(); ++i)
    worst = std::max(worst, std::abs(want->GetTuple1(i) - got->GetTuple1(i)));
  std::printf("check: %s against the in-memory filter: max difference %g over %lld voxels\n",
    aoPath.c_str(), worst, static_cast<long long>(want->GetNumberOfTuples()));
  return worst == 0.0 ? 0 : 1;
}

/// --radius and --method (and --pieces where allowed) from argv[first..]; false on a bad one.
bool ParseOptions(
  int argc, char* argv[], int first, bool piecesAllowed, int& pieces, double& radius, int& method)
{
  for (int i = first; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--pieces" && piecesAllowed && i + 1 < argc)
      pieces = std::atoi(argv[++i]);
    else if (a == "--radius" && i + 1 < argc)
      radius = std::atof(argv[++i]);
    else if (a == "--method" && i + 1 < argc)
    {
      const std::string m = argv[++i];
      if (m == "gaussian")
        method = vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF;
      else if (m == "cdf")
        method = vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION;
      else if (m == "chebyshev")
        method = vtkVolumetricAmbientOcclusion::CHEBYSHEV;
      else if (m == "histogram")
        method = vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF;
      else
        return false;
    }
    else
      return false;
  }
  return pieces >= 1 && radius > 0.0;
}

} // namespace

int main(int argc, char* argv[])
{
  const std::string command = argc > 1 ? argv[1] : "";
  if (command == "generate" && argc == 6)
  {
    const int dims[3] = { std::atoi(argv[3]), std::atoi(argv[4]), std::atoi(argv[5]) };
    if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
      return Usage();
    return Generate(argv[2], dims);
  }
  if ((command != "ao" && command != "check") || argc < 4)
    return Usage();
  int pieces = 16;
  double radius = 10.0;
  int method = vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF;
  if (!ParseOptions(argc, argv, 4, command == "ao", pieces, radius, method))
    return Usage();
  return command == "ao" ? AmbientOcclusion(argv[2], argv[3], pieces, radius, method)
                         : Check(argv[2], argv[3], radius, method);
}
