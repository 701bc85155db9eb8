// libFuzzer target for the points-file reader (`x y [z] volume [material]`).
//
// Input: one option byte, then the file's text. The option byte picks the dimension (1 to 3),
// whether a default material exists, and the section the volumes are divided by (thickness or
// area), including extreme ones so that over- and underflow of cell measures are reached.
//
// Contract checked (a violation aborts, which libFuzzer reports as a crash):
// - bad input only ever throws dhpd::InputError, with a non-empty message naming the file;
// - every point read has finite coordinates, a finite cell measure > 0, a finite spacing > 0
//   and a material index in range.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "engine/base/errors.hpp"
#include "tools/scene/points_file.hpp"

namespace {

[[noreturn]] void contract_broken(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_points: %s: %s\n", what, detail.c_str());
  std::abort();
}

dhpd::scene::PointsFileOptions options_from(std::uint8_t byte) {
  constexpr double kSections[4] = {1.0, 2e-3, 1e-300, 1e300};
  dhpd::scene::PointsFileOptions o;
  o.dim = 1 + byte % 3;
  if ((byte / 3) % 2 == 1) o.default_material = 1;
  o.section = o.dim == 3 ? 1.0 : kSections[(byte / 6) % 4];
  o.materials = {"glass", "steel", "2"};  // "2" is a name that also looks like an index
  return o;
}

void check_points(const dhpd::geometry::PointSet& pts, const dhpd::scene::PointsFileOptions& o) {
  if (pts.size() == 0) contract_broken("accepted a file without points", "");
  for (std::size_t i = 0; i < pts.size(); ++i) {
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(pts.position[i][a])) contract_broken("non-finite coordinate", "");
    if (!(std::isfinite(pts.cell_measure[i]) && pts.cell_measure[i] > 0.0))
      contract_broken("cell measure not finite and > 0", std::to_string(pts.cell_measure[i]));
    if (!(std::isfinite(pts.spacing[i]) && pts.spacing[i] > 0.0))
      contract_broken("spacing not finite and > 0", std::to_string(pts.spacing[i]));
    if (pts.material[i] < 0 || pts.material[i] >= static_cast<int>(o.materials.size()))
      contract_broken("material index out of range", std::to_string(pts.material[i]));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto options = options_from(data[0]);
  std::istringstream in(std::string(reinterpret_cast<const char*>(data) + 1, size - 1));
  try {
    check_points(dhpd::scene::parse_points(in, "fuzz.pts", options), options);
  } catch (const dhpd::InputError& e) {
    if (std::string(e.what()).rfind("fuzz.pts", 0) != 0)
      contract_broken("InputError does not start with the file name", e.what());
  } catch (const std::exception& e) {
    contract_broken("not an InputError", e.what());
  }
  return 0;
}
