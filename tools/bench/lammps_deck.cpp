// LAMMPS peri/pmb side of `dhpd bench`: the deck, the child process, the parsed timings.
// Constants of bond-based PD in 3D (ν = 1/4): K = E / (3(1 − 2ν)), c = 18K / (π δ⁴),
// s0 = sqrt(5 G0 / (9 K δ)) (Silling & Askari 2005; docs/theory.md §3); the LAMMPS step is 0.8 ×
// sqrt(2ρ / Σ_j V_j c / |ξ_j|) over an interior particle's family (docs/theory.md §9).
#include "tools/bench/lammps_deck.hpp"

#include "tools/bench/child_process.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>
#include <vector>

namespace dhpd::bench {

bool Plate::in_notch(int i, int j) const {
  if (i + 0.5 >= 0.25 * nx) return false;
  for (const double y_notch : {0.25 * ny, 0.75 * ny})
    if (std::abs(j + 0.5 - y_notch) < 2.0) return true;
  return false;
}

namespace {

/// Σ_j 1/|ξ_j| / (1/dx) over the lattice offsets within δ (a full interior family).
double inverse_length_sum(double factor) {
  const int reach = static_cast<int>(std::ceil(factor));
  double sum = 0.0;
  for (int a = -reach; a <= reach; ++a)
    for (int b = -reach; b <= reach; ++b)
      for (int c = -reach; c <= reach; ++c) {
        const double r = std::sqrt(double(a * a + b * b + c * c));
        if (r > 0 && r <= factor) sum += 1.0 / r;
      }
  return sum;
}

}  // namespace

std::string lammps_deck(const Plate& p, int steps) {
  const double K = p.E / (3.0 * (1.0 - 2.0 * 0.25));
  const double delta = p.horizon_factor * p.dx;
  const double c = 18.0 * K / (std::numbers::pi * std::pow(delta, 4));
  const double s0 = std::sqrt(5.0 * p.G0 / (9.0 * K * delta));
  const double dt =
      0.8 * std::sqrt(2.0 * p.rho / (c * p.dx * p.dx * inverse_length_sum(p.horizon_factor)));
  const int q = p.nx / 4, y1 = p.ny / 4, y2 = 3 * p.ny / 4;
  std::ostringstream d;
  d << "# dhpd bench: the Kalthoff-Winkler-like plate for LAMMPS peri/pmb (written by dhpd)\n"
    << "units si\nboundary s s s\natom_style peri\natom_modify map array\n"
    << fmt::format("neighbor {:.17g} bin\n", 0.5 * p.dx)
    << "neigh_modify every 1 delay 0 check yes\n"
    << fmt::format("lattice sc {:.17g} origin 0.5 0.5 0.5\n", p.dx)
    << fmt::format("region plate block 0 {} 0 {} 0 {}\n", p.nx, p.ny, p.nz)
    << "create_box 1 plate\ncreate_atoms 1 region plate\n"
    << fmt::format("region n1 block 0 {} {} {} INF INF\n", q, y1 - 2, y1 + 2)
    << fmt::format("region n2 block 0 {} {} {} INF INF\n", q, y2 - 2, y2 + 2)
    << "region notches union 2 n1 n2\ndelete_atoms region notches compress yes\n"
    << "pair_style peri/pmb\n"
    << fmt::format("pair_coeff * * {:.17g} {:.17g} {:.17g} 0.0\n", c, delta, s0)
    << fmt::format("set group all density {:.17g}\n", p.rho)
    << fmt::format("set group all volume {:.17g}\n", p.dx * p.dx * p.dx)
    << fmt::format("region imp block 0 3 {} {} INF INF\ngroup imp region imp\n", y1 + 2, y2 - 2)
    << fmt::format("velocity imp set {:.17g} 0.0 0.0 sum no units box\n", p.impact_speed)
    << "fix 1 all nve\n"
    << fmt::format("timestep {:.17g}\nthermo {}\nrun {}\n", dt, steps, steps);
  return d.str();
}

std::optional<LammpsRun> run_lammps(const std::string& command, const Plate& plate, int steps,
                                    int ranks, std::string& why) {
  namespace fs = std::filesystem;
  std::string dir_template = (fs::temp_directory_path() / "dhpd-bench-XXXXXX").string();
  if (!mkdtemp(dir_template.data())) {
    why = "cannot make a temporary folder";
    return std::nullopt;
  }
  const fs::path dir = dir_template;
  std::ofstream(dir / "in.kw_pmb") << lammps_deck(plate, steps);
  std::vector<std::string> argv;
  if (ranks > 1)
    argv = {"mpirun", "--allow-run-as-root", "--oversubscribe", "-np", std::to_string(ranks)};
  for (const auto& a : {command, std::string("-in"), (dir / "in.kw_pmb").string(),
                        std::string("-log"), std::string("none")})
    argv.push_back(a);
  LammpsRun run;
  const int status =
      run_child(argv, dir / "lmp.out", run.peak_rss_bytes, {{"OMP_NUM_THREADS", "1"}});
  std::ifstream in(dir / "lmp.out");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::error_code ec;
  fs::remove_all(dir, ec);
  std::smatch m;
  const std::regex loop(
      R"(Loop time of ([0-9.eE+-]+) on \d+ procs for \d+ steps with (\d+) atoms)");
  const std::regex pair(R"(\nPair\s*\|\s*[0-9.eE+-]+\s*\|\s*([0-9.eE+-]+))");
  if (status != 0 || !std::regex_search(text, m, loop)) {
    why = fmt::format(
        "{} exited with {}{}", argv[0], status,
        text.empty() ? "" : ": " + text.substr(text.size() > 300 ? text.size() - 300 : 0));
    return std::nullopt;
  }
  run.loop_seconds = std::stod(m[1]);
  run.atoms = std::stol(m[2]);
  if (std::regex_search(text, m, pair)) run.pair_seconds = std::stod(m[1]);
  return run;
}

}  // namespace dhpd::bench
