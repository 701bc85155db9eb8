// The units of every column and array a run writes, kept beside the outputs as units.json so that
// a reader never guesses (SI throughout; "1" is dimensionless, "-" a count or an index).
#pragma once
#include <string>

namespace dhpd::io {

/// units.json: {"history.csv": {column: unit}, "refinement.csv": ..., "cracks.csv": ...,
/// "summary.json": {key: unit}, "frames": {array: unit}}, with a short note per file.
std::string units_json();

}  // namespace dhpd::io
