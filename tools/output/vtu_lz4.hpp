// Frames in VTK's XML unstructured-grid format with LZ4-compressed appended data, written without
// VTK (docs/outputs.md, "Frames"): the same file layout VTK's writer produces (UInt64 headers,
// 32 KiB blocks, one vertex cell per particle), read back by VTK's own reader, but an array whose
// bytes are those of the previous frame (reference points, cells, ids, volumes, ...) keeps its
// compressed blocks instead of being copied and compressed again.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "tools/output/vtk_writer.hpp"

namespace dhpd::io {

class Lz4VtuWriter {
 public:
  /// Writes the frame to `path` (the caller renames it into place). Throws IoError when the file
  /// cannot be written whole.
  void write(const std::filesystem::path& path, double time, std::int64_t step,
             const std::vector<std::string>& materials, const std::vector<double>& points,
             const std::vector<PointField>& fields);

  /// One encoded array: its XML attributes' values and its appended bytes (header and blocks).
  struct Encoded {
    std::uint64_t hash[2] = {0, 0};  ///< XXH3-128 of the bytes it was encoded from
    std::size_t bytes = 0;
    bool valid = false;
    std::string range_min, range_max;
    std::vector<char> appended;
  };
  /// A frame encoded and not yet written: the XML part and the arrays in file order (pointing
  /// into the writer's cache: valid until the next encode_frame or write).
  struct Encoding {
    std::string xml;
    std::vector<const Encoded*> arrays;
  };
  /// The first half of write(): every array encoded (unchanged ones keep their blocks).
  Encoding encode_frame(double time, std::int64_t step, const std::vector<std::string>& materials,
                        const std::vector<double>& points, const std::vector<PointField>& fields);

 private:
  /// The array `key` of this frame: the previous frame's encoding when its `bytes` bytes at
  /// `data` hash the same; `range` gives RangeMin / RangeMax when it is encoded anew.
  const Encoded& encode(const std::string& key, const char* data, std::size_t bytes,
                        const std::function<std::pair<std::string, std::string>()>& range);
  /// The three cell arrays of n vertex cells (encoded again only when n changes).
  std::array<const Encoded*, 3> cells(std::size_t n);
  std::unordered_map<std::string, Encoded> cache_;
};

/// Writes the XML part and then every array's appended bytes, in order, and the closing tags;
/// throws IoError (with the reason, e.g. a full disk) when the file is not written whole.
void write_file(const std::filesystem::path& path, const std::string& xml,
                const std::vector<const Lz4VtuWriter::Encoded*>& arrays);

/// LZ4-compressed appended data of `bytes` bytes at `data` as VTK reads it: UInt64 header
/// (blocks, block size, size of a partial last block or 0, each block's compressed size), then
/// the blocks.
std::vector<char> lz4_appended(const char* data, std::size_t bytes);
/// lz4_appended into `out`, reusing its memory.
void lz4_appended_into(const char* data, std::size_t bytes, std::vector<char>& out);

/// `text` with &, <, > and " escaped for an XML attribute.
std::string xml_escape(const std::string& text);

}  // namespace dhpd::io
