// vao-demo's figure: the input and every method's AO on one slice, a row per method and a
// column per radius (Fig. 6 of Ruiz et al. extended), as a grey-level PNG, read back.
#include "DemoFigure.h"

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGReader.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"

#ifdef VAO_DEMO_HAVE_FREETYPE
#include "vtkFreeTypeTools.h"
#include "vtkStdString.h"
#include "vtkTextProperty.h"
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace vaodemo
{
namespace
{

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
  float At(int x, int y) const
  {
    return this->values[static_cast<std::size_t>(y) * this->width + x];
  }
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
      const vtkIdType id = ijk[0] +
        static_cast<vtkIdType>(dims[0]) * (ijk[1] + static_cast<vtkIdType>(dims[1]) * ijk[2]);
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
  const double u =
    std::clamp((targetIndex + 0.5) * sourceSize / targetSize - 0.5, 0.0, sourceSize - 1.0);
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
      const float top = source.At(tx.first, ty.first) * (1 - tx.weight) +
        source.At(tx.second, ty.first) * tx.weight;
      const float bottom = source.At(tx.first, ty.second) * (1 - tx.weight) +
        source.At(tx.second, ty.second) * tx.weight;
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
  return { static_cast<int>(std::lround(width * zoom)),
    static_cast<int>(std::lround(height * zoom)) };
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
  if (freeType->RenderString(property, vtkStdString(text), 72, image, size) && size[0] > 0 &&
    size[1] > 0 && image->GetNumberOfScalarComponents() == 4)
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
  auto rendered = [](const std::vector<Raster>& r)
  { return std::all_of(r.begin(), r.end(), [](const Raster& label) { return label.width > 0; }); };
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
  const int gridLeft = Margin + labelWidth, pitchX = cellSize[0] + Separator,
            pitchY = cellSize[1] + Separator;
  const int methodsTop = Margin + cellSize[1] + headerHeight;
  Raster canvas(gridLeft + columns * pitchX - Separator + Margin,
    methodsTop + methodRows * pitchY - Separator + Margin, Background);

  // The method grid on a separator-grey ground: the gaps between cells stay grey.
  Paste(canvas,
    Raster(columns * pitchX - Separator, methodRows * pitchY - Separator, SeparatorGrey), gridLeft,
    methodsTop, false);
  for (std::size_t row = 0; row < content.rows.size(); ++row)
  {
    const int top = row == 0 ? Margin : methodsTop + static_cast<int>(row - 1) * pitchY;
    for (std::size_t column = 0; column < content.rows[row].size(); ++column)
    {
      Paste(canvas, content.rows[row][column], gridLeft + static_cast<int>(column) * pitchX, top,
        false);
    }
    if (!labels.Empty())
    {
      Paste(
        canvas, labels.rows[row], Margin, top + (cellSize[1] - labels.rows[row].height) / 2, true);
    }
  }
  for (std::size_t column = 0; column < labels.columns.size(); ++column)
  {
    const Raster& label = labels.columns[column];
    Paste(canvas, label,
      gridLeft + static_cast<int>(column) * pitchX + (cellSize[0] - label.width) / 2,
      Margin + cellSize[1] + (headerHeight - label.height) / 2, true);
  }
  return canvas;
}

FigureContent BuildFigureContent(vtkImageData* image, vtkDataArray* scalars,
  const std::vector<Computation>& results, const std::vector<int>& radii, int sliceAxis)
{
  FigureContent content;
  content.cellSize = CellSize(image, sliceAxis);
  auto cell = [&](vtkDataArray* values)
  {
    return Resample(
      ExtractSlice(image, values, sliceAxis), content.cellSize[0], content.cellSize[1]);
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
      content.rows.back().push_back(
        cell(Find(results, &method, radius).values)); // AO is in [0, 1] already
    }
  }
  return content;
}

/// Without text rendering the layout goes to stdout and to a .txt beside the PNG.
void WriteLegend(const FigureContent& content, const std::string& pngPath)
{
  std::string legend = "Layout of " + pngPath +
    " (no text rendering available):\n  row 1, column 1: " + content.rowLabels[0] +
    "\n  columns, left to right:";
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

} // namespace

void WriteFigure(vtkImageData* image, vtkDataArray* scalars,
  const std::vector<Computation>& results, const std::vector<int>& radii, int sliceAxis,
  const std::string& path)
{
  const FigureContent content = BuildFigureContent(image, scalars, results, radii, sliceAxis);
  const Labels labels = RenderLabels(content);
  const Raster canvas = ComposeFigure(content, labels);
  if (labels.Empty())
  {
    WriteLegend(content, path);
  }
  WritePng(canvas, path);
  CheckPngReadBack(canvas, path);
}

} // namespace vaodemo
