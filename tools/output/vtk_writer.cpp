// VTK XML frame output and read-back. This is the only translation unit that sees VTK headers.
#include "tools/output/vtk_writer.hpp"

#include <fmt/format.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkVariant.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace dhpd::io {
namespace {

namespace fs = std::filesystem;

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string xml_unescape(const std::string& text) {
  static constexpr std::pair<const char*, char> kEntities[] = {
      {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    bool replaced = false;
    if (text[i] == '&') {
      for (const auto& [entity, ch] : kEntities) {
        if (text.compare(i, std::char_traits<char>::length(entity), entity) == 0) {
          out += ch;
          i += std::char_traits<char>::length(entity) - 1;
          replaced = true;
          break;
        }
      }
    }
    if (!replaced) out += text[i];
  }
  return out;
}

/// Renames `from` onto `to`; on failure removes `from` and throws with both paths.
void commit_file(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) {
    fs::remove(from, ec);
    throw std::runtime_error(
        fmt::format("cannot rename '{}' to '{}': {}", from.string(), to.string(), ec.message()));
  }
}

void ensure_directory(const fs::path& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw std::runtime_error(
        fmt::format("cannot create output directory '{}': {}", dir.string(), ec.message()));
  }
}

std::size_t value_count(const PointField& field) {
  return std::visit([](const auto& v) { return v.size(); }, field.values);
}

vtkSmartPointer<vtkDataArray> make_point_array(const PointField& field, std::size_t n) {
  if (field.components < 1 ||
      value_count(field) != n * static_cast<std::size_t>(field.components)) {
    throw std::invalid_argument(fmt::format("point field '{}': {} values for {} points x {} comps",
                                            field.name, value_count(field), n, field.components));
  }
  vtkSmartPointer<vtkDataArray> array;
  if (const auto* d = std::get_if<std::vector<double>>(&field.values)) {
    auto a = vtkSmartPointer<vtkDoubleArray>::New();
    a->SetNumberOfComponents(field.components);
    a->SetNumberOfTuples(static_cast<vtkIdType>(n));
    std::copy(d->begin(), d->end(), a->GetPointer(0));
    array = a;
  } else {
    const auto& v = std::get<std::vector<std::int32_t>>(field.values);
    auto a = vtkSmartPointer<vtkIntArray>::New();
    a->SetNumberOfComponents(field.components);
    a->SetNumberOfTuples(static_cast<vtkIdType>(n));
    std::copy(v.begin(), v.end(), a->GetPointer(0));
    array = a;
  }
  array->SetName(field.name.c_str());
  return array;
}

void add_time_data(vtkUnstructuredGrid* grid, double time, std::int64_t step) {
  auto time_array = vtkSmartPointer<vtkDoubleArray>::New();
  time_array->SetName("TimeValue");
  time_array->SetNumberOfTuples(1);
  time_array->SetValue(0, time);
  auto step_array = vtkSmartPointer<vtkTypeInt64Array>::New();
  step_array->SetName("Step");
  step_array->SetNumberOfTuples(1);
  step_array->SetValue(0, step);
  grid->GetFieldData()->AddArray(time_array);
  grid->GetFieldData()->AddArray(step_array);
}

vtkSmartPointer<vtkUnstructuredGrid> make_grid(const std::vector<double>& points,
                                               const std::vector<PointField>& fields) {
  if (points.size() % 3 != 0) {
    throw std::invalid_argument(
        fmt::format("point coordinates: {} is not a multiple of 3", points.size()));
  }
  const std::size_t n = points.size() / 3;
  auto coords = vtkSmartPointer<vtkPoints>::New();
  coords->SetDataType(VTK_DOUBLE);
  coords->SetNumberOfPoints(static_cast<vtkIdType>(n));
  auto* raw = vtkDoubleArray::SafeDownCast(coords->GetData());
  std::copy(points.begin(), points.end(), raw->GetPointer(0));

  // One VTK_VERTEX per particle: offsets 0..n, connectivity 0..n-1.
  auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
  auto connectivity = vtkSmartPointer<vtkIdTypeArray>::New();
  offsets->SetNumberOfTuples(static_cast<vtkIdType>(n + 1));
  connectivity->SetNumberOfTuples(static_cast<vtkIdType>(n));
  for (vtkIdType i = 0; i <= static_cast<vtkIdType>(n); ++i) offsets->SetValue(i, i);
  for (vtkIdType i = 0; i < static_cast<vtkIdType>(n); ++i) connectivity->SetValue(i, i);
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  cells->SetData(offsets, connectivity);

  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(coords);
  grid->SetCells(VTK_VERTEX, cells);
  for (const PointField& field : fields) {
    grid->GetPointData()->AddArray(make_point_array(field, n));
  }
  return grid;
}

void write_vtu(vtkUnstructuredGrid* grid, const fs::path& final_path) {
  const fs::path tmp = fs::path(final_path).concat(".tmp");
  auto writer = vtkSmartPointer<vtkXMLUnstructuredGridWriter>::New();
  writer->SetFileName(tmp.c_str());
  writer->SetInputData(grid);
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetHeaderTypeToUInt64();
  // Instantiates vtkZLibDataCompressor inside IOXML, so no direct link to VTK::IOCore is needed.
  writer->SetCompressorTypeToZLib();
  if (writer->Write() != 1) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write VTK file '{}'", tmp.string()));
  }
  commit_file(tmp, final_path);
}

/// Reads attribute `key` of one XML tag into `value`; false when the attribute is absent.
bool tag_attribute(const std::string& tag, const std::string& key, std::string& value) {
  const std::string needle = " " + key + "=\"";
  std::size_t pos = tag.find(needle);
  if (pos == std::string::npos) return false;
  pos += needle.size();
  const std::size_t end = tag.find('"', pos);
  if (end == std::string::npos) return false;
  value = xml_unescape(tag.substr(pos, end - pos));
  return true;
}

}  // namespace

FrameSeries::FrameSeries(std::string directory, std::string name)
    : directory_(std::move(directory)), name_(std::move(name)) {}

void FrameSeries::write(double time, std::int64_t step, const std::vector<double>& points,
                        const std::vector<PointField>& fields) {
  ensure_directory(directory_);
  const std::string file = fmt::format("{}_{:06d}.vtu", name_, entries_.size());
  auto grid = make_grid(points, fields);
  add_time_data(grid, time, step);
  write_vtu(grid, fs::path(directory_) / file);
  entries_.emplace_back(time, file);
  write_pvd();
}

void FrameSeries::resume(std::vector<std::pair<double, std::string>> entries) {
  ensure_directory(directory_);
  entries_ = std::move(entries);
  write_pvd();
}

void FrameSeries::write_pvd() const {
  std::string text =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const auto& [time, file] : entries_) {
    text += fmt::format("    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
                        time, xml_escape(file));
  }
  text += "  </Collection>\n</VTKFile>\n";

  const fs::path final_path = fs::path(directory_) / (name_ + ".pvd");
  const fs::path tmp = fs::path(final_path).concat(".tmp");
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error(fmt::format("cannot write '{}'", tmp.string()));
    }
  }
  commit_file(tmp, final_path);
}

Frame read_frame(const std::string& vtu_path) {
  std::error_code ec;
  if (!fs::is_regular_file(vtu_path, ec)) {
    throw std::runtime_error(fmt::format("no such VTK file '{}'", vtu_path));
  }
  auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  if (!reader->CanReadFile(vtu_path.c_str())) {
    throw std::runtime_error(fmt::format("not a VTK unstructured grid file '{}'", vtu_path));
  }
  reader->SetFileName(vtu_path.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  if (reader->GetErrorCode() != 0 || grid == nullptr) {
    throw std::runtime_error(fmt::format("cannot read VTK file '{}'", vtu_path));
  }

  Frame frame;
  if (vtkPoints* pts = grid->GetPoints()) {
    frame.points.resize(static_cast<std::size_t>(pts->GetNumberOfPoints()) * 3);
    for (vtkIdType i = 0; i < pts->GetNumberOfPoints(); ++i) pts->GetPoint(i, &frame.points[3 * i]);
  }
  vtkPointData* pd = grid->GetPointData();
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a) {
    vtkDataArray* array = pd->GetArray(a);
    if (array == nullptr || array->GetName() == nullptr) continue;
    const int comps = array->GetNumberOfComponents();
    std::vector<double> values(static_cast<std::size_t>(array->GetNumberOfTuples()) * comps);
    for (vtkIdType t = 0; t < array->GetNumberOfTuples(); ++t) {
      for (int c = 0; c < comps; ++c) values[t * comps + c] = array->GetComponent(t, c);
    }
    frame.fields[array->GetName()] = {comps, std::move(values)};
    frame.field_types[array->GetName()] = array->GetDataTypeAsString();
  }
  vtkFieldData* fd = grid->GetFieldData();
  if (vtkDataArray* t = fd->GetArray("TimeValue"); t && t->GetNumberOfTuples() > 0) {
    frame.time = t->GetComponent(0, 0);
  }
  if (vtkAbstractArray* s = fd->GetAbstractArray("Step"); s && s->GetNumberOfTuples() > 0) {
    frame.step = s->GetVariantValue(0).ToTypeInt64();
  }
  return frame;
}

std::vector<std::pair<double, std::string>> read_pvd(const std::string& pvd_path) {
  std::ifstream in(pvd_path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot open '{}'", pvd_path));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  // A whole XML document with a VTKFile root and a Collection (VTK's own XML parser).
  auto parser = vtkSmartPointer<vtkXMLDataParser>::New();
  auto quiet = vtkSmartPointer<vtkCallbackCommand>::New();  // the error is ours to report
  parser->AddObserver(vtkCommand::ErrorEvent, quiet);
  std::istringstream xml(text);
  parser->SetStream(&xml);
  vtkXMLDataElement* root = parser->Parse() ? parser->GetRootElement() : nullptr;
  if (!root || std::string(root->GetName()) != "VTKFile" ||
      !root->FindNestedElementWithName("Collection"))
    throw std::runtime_error(fmt::format("'{}' is not a whole VTK collection file", pvd_path));

  std::vector<std::pair<double, std::string>> entries;
  for (std::size_t pos = text.find("<DataSet"); pos != std::string::npos;
       pos = text.find("<DataSet", pos + 1)) {
    const std::size_t end = text.find('>', pos);
    if (end == std::string::npos) break;
    const std::string tag = text.substr(pos, end - pos);
    std::string time_text, file;
    if (!tag_attribute(tag, "timestep", time_text) || !tag_attribute(tag, "file", file)) {
      throw std::runtime_error(fmt::format("malformed DataSet entry in '{}'", pvd_path));
    }
    char* parsed_end = nullptr;
    const double time = std::strtod(time_text.c_str(), &parsed_end);
    if (parsed_end == time_text.c_str()) {
      throw std::runtime_error(fmt::format("bad timestep '{}' in '{}'", time_text, pvd_path));
    }
    entries.emplace_back(time, file);
  }
  return entries;
}

}  // namespace dhpd::io
