// Test-only read-back of the VTK output (tools/output/vtk_writer.hpp): a .vtu frame through VTK's
// XML reader and the entries of a .pvd collection. Compiled into the test-support library
// dhpd_test_vtk_read (tests/CMakeLists.txt), never into a production library.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace dhpd::io {

/// A frame read back with VTK's XML reader.
struct Frame {
  double time = 0.0;
  std::int64_t step = -1;
  std::vector<double> points;  ///< 3 per particle
  std::map<std::string, std::pair<int, std::vector<double>>>
      fields;                                      ///< name → (components, values)
  std::map<std::string, std::string> field_types;  ///< name → VTK data type name ("double", "int")
};
Frame read_frame(const std::string& vtu_path);

/// (time, file) entries of a .pvd collection, in file order, times parsed at full precision.
std::vector<std::pair<double, std::string>> read_pvd(const std::string& pvd_path);

}  // namespace dhpd::io
