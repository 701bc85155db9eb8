// VTK XML output: one .vtu per frame (binary, LZ4-, zlib- or un-compressed, double-precision
// points, one vertex cell per particle) and a .pvd collection that is rewritten atomically after
// every frame. VTK headers stay inside vtk_writer.cpp. Frames are read back only by the tests
// (tests/support/vtk_read.hpp).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace dhpd::io {

class Lz4VtuWriter;

/// A named point array, interleaved by component (x0 y0 z0 x1 y1 z1 ...).
struct PointField {
  std::string name;
  int components = 1;
  std::variant<std::vector<double>, std::vector<std::int32_t>> values;
};

/// How the binary arrays of a frame are compressed; the decoded content is the same for each.
enum class Compression { lz4, zlib, none };

/// Writes frames `<directory>/<name>_<k>.vtu` and keeps `<directory>/<name>.pvd` valid after each.
class FrameSeries {
 public:
  /// `materials`: the scene's material names, in index order; every frame carries them as field
  /// data `material_names` (the `material` point array indexes it).
  FrameSeries(std::string directory, std::string name, std::vector<std::string> materials = {},
              Compression compression = Compression::lz4);
  /// `points` holds 3 doubles per particle. Writes to a temporary file, then renames.
  void write(double time, std::int64_t step, const std::vector<double>& points,
             const std::vector<PointField>& fields);
  /// write() in two parts, for a frame written over two force passes: prepare() checks and
  /// encodes the frame (LZ4; zlib and none write it whole here), commit() writes its file and
  /// lists it in the .pvd. Between them nothing but commit() is called.
  void prepare(double time, std::int64_t step, const std::vector<double>& points,
               const std::vector<PointField>& fields);
  void commit();
  std::size_t frames_written() const { return entries_.size(); }
  /// The file name the next frame gets (also while one is prepared and not committed).
  std::string next_file() const;
  /// (time, file) of every frame listed in the .pvd.
  const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
  /// Continues a series whose frames `entries` exist (a restart): rewrites the .pvd to list
  /// exactly them; the next frame gets the next number.
  void resume(std::vector<std::pair<double, std::string>> entries);

 private:
  void write_pvd() const;
  std::string directory_, name_;
  std::vector<std::string> materials_;
  Compression compression_;
  /// The LZ4 frames' writer and its encoded arrays (vtu_lz4.hpp); null for zlib and none, which
  /// VTK writes.
  std::shared_ptr<Lz4VtuWriter> lz4_;
  struct Prepared;
  std::shared_ptr<Prepared> prepared_;                   ///< between prepare() and commit() (LZ4)
  std::vector<std::pair<double, std::string>> entries_;  ///< (time, file name)
};

}  // namespace dhpd::io
