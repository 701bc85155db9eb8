// The version of dhpd and the commit of the source tree it was built from (cmake/version.cmake
// writes their definitions at every build: "unknown" outside a git checkout, "-dirty" when the
// tree had uncommitted changes).
#pragma once

namespace dhpd {
const char* dhpd_version();
const char* dhpd_commit();
}  // namespace dhpd
