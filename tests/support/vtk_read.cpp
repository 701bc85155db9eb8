// VTK read-back for the tests (see vtk_read.hpp).
#include "tests/support/vtk_read.hpp"

#include <fmt/format.h>
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkVariant.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace dhpd::io {
namespace {

namespace fs = std::filesystem;

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
