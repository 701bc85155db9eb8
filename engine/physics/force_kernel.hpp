// The force kernel of one bond row (docs/theory.md §4, §18): f_i = Σ_k c_k s_k n_k with
// c_k = K_k V_k and the fused break test. Two builds of the same arithmetic: plain C++ and AVX2
// (chosen once per call from the CPU). Both sum a row in four lanes (entry t of a row goes to lane
// t mod 4, lanes added as (0 + 1) + (2 + 3)) with the same IEEE operations in the same order and no
// fused multiply-add, so they give the same bits on every machine and for every thread count.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/physics/interactions.hpp"

namespace dhpd::kernel {

/// Views of the row arrays the kernel streams (taken once per call, never per bond), with the
/// particle volumes the pair stiffness is multiplied by.
struct RowArrays {
  const std::int64_t* start;
  const std::int32_t* count;
  const std::int32_t* other;
  const std::int32_t* length_index;
  const double* inverse_lengths;  ///< the table length_index points into
  const float* stiffness;
  const std::uint8_t* flags;
  const double* break_ratio2;
  const double* volume;
  double scale;

  RowArrays(const BondRows& b, const ParticleStore& p)
      : start(b.rows.start.data()),
        count(b.rows.count.data()),
        other(b.other.data()),
        length_index(b.length_index.data()),
        inverse_lengths(b.inverse_lengths.data()),
        stiffness(b.stiffness.data()),
        flags(b.flags.data()),
        break_ratio2(b.break_ratio2.data()),
        volume(p.volume.data()),
        scale(b.stiffness_scale) {}

  /// 1/|ξ| of entry k.
  double inverse_length(std::int64_t k) const { return inverse_lengths[length_index[k]]; }
};

/// The stretch watch fused into the break test (docs/theory.md §13.1): with `hit` set, each row i
/// of a pass writes hit[i] = 1 when one of its own bonds, still intact after the row's breaks, has
/// a squared stretch ratio ≥ limit_ratio2[i], else 0. (The fast test of a block is against the
/// lower of this limit and the row's break_ratio2, which its dual entries may set below it.)
struct StretchWatch {
  const double* limit_ratio2 = nullptr;
  std::uint8_t* hit = nullptr;
};

/// What the fused break test needs on its slow path (unused by the elastic kernel).
struct Breaking {
  BondRows* rows = nullptr;
  const BondConstants* constants = nullptr;
  StretchWatch watch{};
};

/// Positions read and force densities written (the first Dim axes); the kernels with Energy also
/// write each row's Σ_k c_k s_k² |ξ_k| (the sum RowEnergy returns) to energy[i]. `points` holds
/// y_0, y_1, y_2, V of each particle side by side (pack_points): the AVX2 build loads a
/// neighbour's position and volume with one 32-byte load, four neighbours transposed in registers.
struct Fields {
  const double* y[3];
  double* f[3];
  double* energy = nullptr;
  const double* points = nullptr;
};

/// Writes y_0, y_1, y_2, V of every particle to `out` (4 per particle; unused axes 0), in parallel.
void pack_points(const ParticleStore& p, std::vector<double>& out);

/// Packed points kept between force passes. `fresh`: the owner wrote the current positions and
/// volumes into `xyzv` since the last pass (a time step's integrator does); a pass packs them
/// itself otherwise, and clears `fresh` after use, so nothing else can leave them stale.
struct PackedPoints {
  std::vector<double> xyzv;
  bool fresh = false;
};

/// Force density of row i; with Fracture, entries with an intact bond whose squared stretch ratio
/// (|y|/|ξ|)² reached the row's break_ratio2 go through break_entry first, on that ratio; with
/// Energy, the row's energy after its break tests, the same bits as RowEnergy gives after the pass.
/// Returns the own bonds broken.
using RowKernel = std::int64_t (*)(std::int64_t i, const Fields& x, const RowArrays& r,
                                   const Breaking& w);

/// Σ_k c_k s_k² |ξ_k| of row i (the pair energy of docs/theory.md §3 before ¼ V_i), from the
/// positions y (first Dim axes); entries with c_k = 0 add exactly 0. Same lanes and order in
/// both builds, so the same bits.
using RowEnergy = double (*)(std::int64_t i, const double* const y[3], const RowArrays& r);

enum class Build { Plain, Avx2 };

/// Whether this CPU runs the AVX2 build.
bool avx2_available();
/// The fastest build this CPU runs (AVX2 when available).
inline Build best_build() {
  return avx2_available() ? Build::Avx2 : Build::Plain;
}

/// The row kernel of a build (Avx2 on a CPU without it falls back to Plain).
template <int Dim, bool Fracture, bool Energy = false>
RowKernel row_kernel(Build build);

/// The row energy of a build (Avx2 on a CPU without it falls back to Plain).
template <int Dim>
RowEnergy row_energy_kernel(Build build);

}  // namespace dhpd::kernel
