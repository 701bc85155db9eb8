// VTK XML output: one .vtu per frame (binary, zlib-compressed, double-precision points, one vertex
// cell per particle) and a .pvd collection that is rewritten atomically after every frame.
// VTK headers stay inside vtk_writer.cpp.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace dhpd::io {

/// A named point array, interleaved by component (x0 y0 z0 x1 y1 z1 ...).
struct PointField {
  std::string name;
  int components = 1;
  std::variant<std::vector<double>, std::vector<std::int32_t>> values;
};

/// Writes frames `<directory>/<name>_<k>.vtu` and keeps `<directory>/<name>.pvd` valid after each.
class FrameSeries {
 public:
  FrameSeries(std::string directory, std::string name);
  /// `points` holds 3 doubles per particle. Writes to a temporary file, then renames.
  void write(double time, std::int64_t step, const std::vector<double>& points,
             const std::vector<PointField>& fields);
  std::size_t frames_written() const { return entries_.size(); }
  /// (time, file) of every frame listed in the .pvd.
  const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
  /// Continues a series whose frames `entries` exist (a restart): rewrites the .pvd to list
  /// exactly them; the next frame gets the next number.
  void resume(std::vector<std::pair<double, std::string>> entries);

 private:
  void write_pvd() const;
  std::string directory_, name_;
  std::vector<std::pair<double, std::string>> entries_;  ///< (time, file name)
};

/// A frame read back with VTK's XML reader (for tests and post-processing).
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
