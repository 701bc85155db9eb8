// Force kernel of one bond row, plain and AVX2 (docs/theory.md §4, §18).
#include "engine/physics/force_kernel.hpp"
#include "engine/base/parallel.hpp"
#include "engine/physics/bond_law.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define DHPD_HAS_AVX2_BUILD 1
#endif

namespace dhpd::kernel {
namespace {

/// c s² |ξ| of an entry from its squared deformed length, s = |y| / |ξ| − 1 with 1/|ξ| stored
/// (eq. 3.1); 0 exactly when c = 0. The AVX2 builds do the same operations lane by lane.
inline double energy_of_entry(double l2, double c, double inv_length) {
  const double s = std::sqrt(l2) * inv_length - 1.0;
  return c != 0.0 ? c * s * s / inv_length : 0.0;
}

/// Whether an entry still has an intact bond (a broken pair never goes down the slow path).
inline bool has_intact(std::uint8_t flags) {
  return (flags & (kOwnIntact | kDualIntact)) != 0;
}

/// c = K V_other of entry k: the stored pair stiffness times the scale (exact: a power of two)
/// times the other particle's volume.
inline double coefficient_of(const RowArrays& r, std::int64_t k, std::int32_t j) {
  return static_cast<double>(r.stiffness[k]) * r.scale * r.volume[j];
}

/// Whether one of the `n` entries from k, with squared ratios ratio2, is an own bond still intact
/// (after the row's breaks) at or beyond row i's watch limit (StretchWatch).
inline bool watched(std::int64_t i, std::int64_t k, int n, const double ratio2[],
                    const RowArrays& r, const Breaking& w) {
  for (int t = 0; t < n; ++t)
    if (ratio2[t] >= w.watch.limit_ratio2[i] && (r.flags[k + t] & kOwnIntact)) return true;
  return false;
}

/// One entry in plain arithmetic: the same operations as a lane of the AVX2 build. With Energy,
/// the entry's c s² |ξ| (after its break test) is added to `energy`.
template <int Dim, bool Fracture, bool Energy>
inline int entry(std::int64_t i, std::int64_t k, const double yi[Dim], const Fields& x,
                 const RowArrays& r, const Breaking& w, double lane[Dim], double& energy,
                 bool& seen) {
  const std::int32_t j = r.other[k];
  double dx[Dim], l2 = 0.0;
  for (int a = 0; a < Dim; ++a) dx[a] = x.y[a][j] - yi[a], l2 += dx[a] * dx[a];
  int broken = 0;
  if constexpr (Fracture) {
    const double ratio2 = bond_law::stretch_ratio2(l2, r.inverse_length(k));
    if (ratio2 >= r.break_ratio2[i] && has_intact(r.flags[k])) [[unlikely]]
      broken = break_entry(*w.rows, static_cast<std::size_t>(i), k, ratio2, *w.constants);
    if (w.watch.hit && !seen && ratio2 >= w.watch.limit_ratio2[i]) [[unlikely]]
      seen = watched(i, k, 1, &ratio2, r, w);
  }
  const double c = coefficient_of(r, k, j);
  const double s = c * (r.inverse_length(k) - 1.0 / std::sqrt(l2));
  for (int a = 0; a < Dim; ++a) lane[a] += s * dx[a];
  if constexpr (Energy) energy += energy_of_entry(l2, c, r.inverse_length(k));
  return broken;
}

inline double sum_lanes(const double lane[4]) {
  return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}

template <int Dim, bool Energy>
inline void write_force(std::int64_t i, const Fields& x, const double lanes[Dim][4],
                        const double energy_lanes[4]) {
  for (int a = 0; a < Dim; ++a) x.f[a][i] = sum_lanes(lanes[a]);
  if constexpr (Energy) x.energy[i] = sum_lanes(energy_lanes);
}

/// The slow path of a block of four entries from k: break_entry for each lane set in `hit`.
/// Kept out of line so the vector loop keeps its registers.
[[gnu::noinline, gnu::cold]] std::int64_t break_block(std::int64_t i, std::int64_t k, int hit,
                                                      const double ratio2[4], const Breaking& w) {
  std::int64_t broken = 0;
  for (int t = 0; t < 4; ++t)
    if (hit & (1 << t))
      broken += break_entry(*w.rows, static_cast<std::size_t>(i), k + t, ratio2[t], *w.constants);
  return broken;
}

/// Entries [from, end) of row i in plain arithmetic, entry k into lane (k − row start) mod 4.
template <int Dim, bool Fracture, bool Energy>
std::int64_t plain_entries(std::int64_t i, std::int64_t from, const Fields& x, const RowArrays& r,
                           const Breaking& w, double lanes[Dim][4], double energy_lanes[4],
                           bool& seen) {
  double yi[Dim];
  for (int a = 0; a < Dim; ++a) yi[a] = x.y[a][i];
  std::int64_t broken = 0;
  const std::int64_t begin = r.start[i], end = begin + r.count[i];
  for (std::int64_t k = from; k < end; ++k) {
    const auto t = static_cast<int>((k - begin) & 3);
    double lane[Dim];
    for (int a = 0; a < Dim; ++a) lane[a] = lanes[a][t];
    broken += entry<Dim, Fracture, Energy>(i, k, yi, x, r, w, lane, energy_lanes[t], seen);
    for (int a = 0; a < Dim; ++a) lanes[a][t] = lane[a];
  }
  return broken;
}

/// c s² |ξ| of entry k of row i in plain arithmetic.
template <int Dim>
inline double entry_energy(std::int64_t i, std::int64_t k, const double* const y[3],
                           const RowArrays& r) {
  const std::int32_t j = r.other[k];
  double l2 = 0.0;
  for (int a = 0; a < Dim; ++a) {
    const double d = y[a][j] - y[a][i];
    l2 += d * d;
  }
  return energy_of_entry(l2, coefficient_of(r, k, j), r.inverse_length(k));
}

template <int Dim>
double energy_plain_from(std::int64_t i, std::int64_t from, const double* const y[3],
                         const RowArrays& r, double lane[4]) {
  const std::int64_t begin = r.start[i], end = begin + r.count[i];
  for (std::int64_t k = from; k < end; ++k) lane[(k - begin) & 3] += entry_energy<Dim>(i, k, y, r);
  return sum_lanes(lane);
}

template <int Dim>
double energy_plain(std::int64_t i, const double* const y[3], const RowArrays& r) {
  double lane[4] = {0.0, 0.0, 0.0, 0.0};
  return energy_plain_from<Dim>(i, r.start[i], y, r, lane);
}

template <int Dim, bool Fracture, bool Energy>
std::int64_t row_plain(std::int64_t i, const Fields& x, const RowArrays& r, const Breaking& w) {
  double lanes[Dim][4] = {}, energy_lanes[4] = {0.0, 0.0, 0.0, 0.0};
  bool seen = false;
  const auto broken =
      plain_entries<Dim, Fracture, Energy>(i, r.start[i], x, r, w, lanes, energy_lanes, seen);
  write_force<Dim, Energy>(i, x, lanes, energy_lanes);
  if (Fracture && w.watch.hit) w.watch.hit[i] = seen ? 1 : 0;
  return broken;
}

#ifdef DHPD_HAS_AVX2_BUILD
#pragma GCC push_options
#pragma GCC target("avx2")
/// c s² |ξ| of four entries, 0 where c = 0 (the lanes of energy_of_entry).
inline __m256d energy_of_entries(__m256d root_l2, __m256d c, __m256d inv) {
  const __m256d s = _mm256_sub_pd(_mm256_mul_pd(root_l2, inv), _mm256_set1_pd(1.0));
  const __m256d e = _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(c, s), s), inv);
  return _mm256_and_pd(e, _mm256_cmp_pd(c, _mm256_setzero_pd(), _CMP_NEQ_UQ));
}

/// c = K V_other of the four entries from k (the lanes of coefficient_of), V_other in `volume`.
inline __m256d coefficients(const RowArrays& r, std::int64_t k, __m256d volume) {
  const __m256d K =
      _mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(r.stiffness + k)), _mm256_set1_pd(r.scale));
  return _mm256_mul_pd(K, volume);
}

/// y_0, y_1, y_2 and V of the particles j[0..3] from the packed points: four 32-byte loads
/// transposed, so out[a] holds component a of the four.
inline void neighbours(const double* points, const std::int32_t* j, __m256d out[4]) {
  const __m256d a0 = _mm256_loadu_pd(points + 4 * static_cast<std::int64_t>(j[0]));
  const __m256d a1 = _mm256_loadu_pd(points + 4 * static_cast<std::int64_t>(j[1]));
  const __m256d a2 = _mm256_loadu_pd(points + 4 * static_cast<std::int64_t>(j[2]));
  const __m256d a3 = _mm256_loadu_pd(points + 4 * static_cast<std::int64_t>(j[3]));
  const __m256d t0 = _mm256_unpacklo_pd(a0, a1), t1 = _mm256_unpackhi_pd(a0, a1);
  const __m256d t2 = _mm256_unpacklo_pd(a2, a3), t3 = _mm256_unpackhi_pd(a2, a3);
  out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/// 1/|ξ| of four entries from the table, given their indices (four scalar loads: on the CPUs
/// measured, faster than a gather instruction).
inline __m256d inverse_lengths_of(const double* table, const std::int32_t* index) {
  return _mm256_set_pd(table[index[3]], table[index[2]], table[index[1]], table[index[0]]);
}

/// Lanes of the four entries from k that still hold an intact bond (has_intact).
inline __m256d intact_lanes(const RowArrays& r, std::int64_t k) {
  std::int32_t bytes = 0;
  std::memcpy(&bytes, r.flags + k, sizeof bytes);
  const __m256i f = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(bytes));
  const __m256i bits = _mm256_and_si256(f, _mm256_set1_epi64x(kOwnIntact | kDualIntact));
  return _mm256_castsi256_pd(
      _mm256_xor_si256(_mm256_cmpeq_epi64(bits, _mm256_setzero_si256()), _mm256_set1_epi64x(-1)));
}

/// The last `rest` (1–3) entries of row i from k, in lanes 0..rest−1 (the lanes plain_entries
/// gives them, with the same operations); the other lanes point at i itself and add −0.0, the
/// identity of IEEE addition, so the lanes' sums keep their bits.
template <int Dim, bool Fracture, bool Energy>
std::int64_t tail_avx2(std::int64_t i, std::int64_t k, int rest, const __m256d yi[Dim],
                       const Fields& x, const RowArrays& r, const Breaking& w, __m256d acc[Dim],
                       __m256d& energy, bool& seen) {
  const auto self = static_cast<std::int32_t>(i);
  std::int32_t j[4] = {self, self, self, self};
  alignas(32) double inv_lanes[4] = {1.0, 1.0, 1.0, 1.0};
  for (int t = 0; t < rest; ++t) j[t] = r.other[k + t], inv_lanes[t] = r.inverse_length(k + t);
  const __m256d valid = _mm256_castsi256_pd(
      _mm256_cmpgt_epi64(_mm256_set1_epi64x(rest), _mm256_set_epi64x(3, 2, 1, 0)));
  const __m256d one = _mm256_set1_pd(1.0), minus_zero = _mm256_set1_pd(-0.0);
  __m256d dx[Dim], l2 = _mm256_setzero_pd();
  for (int a = 0; a < Dim; ++a) {
    const double* ya = x.y[a];
    dx[a] = _mm256_sub_pd(_mm256_set_pd(ya[j[3]], ya[j[2]], ya[j[1]], ya[j[0]]), yi[a]);
    l2 = _mm256_add_pd(l2, _mm256_mul_pd(dx[a], dx[a]));
  }
  l2 = _mm256_blendv_pd(one, l2, valid);  // no 1/0 in the unused lanes
  const __m256d inv = _mm256_load_pd(inv_lanes);
  std::int64_t broken = 0;
  if constexpr (Fracture) {
    alignas(32) double ratios[4];
    _mm256_store_pd(ratios, _mm256_mul_pd(_mm256_mul_pd(l2, inv), inv));
    int hit = 0;
    for (int t = 0; t < rest; ++t)
      if (ratios[t] >= r.break_ratio2[i] && has_intact(r.flags[k + t])) hit |= 1 << t;
    if (hit) [[unlikely]]
      broken = break_block(i, k, hit, ratios, w);
    if (w.watch.hit && !seen) seen = watched(i, k, rest, ratios, r, w);
  }
  alignas(16) float K[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // read after the breaks
  for (int t = 0; t < rest; ++t) K[t] = r.stiffness[k + t];
  const double* V = r.volume;
  const __m256d c =
      _mm256_mul_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm_load_ps(K)), _mm256_set1_pd(r.scale)),
                    _mm256_set_pd(V[j[3]], V[j[2]], V[j[1]], V[j[0]]));
  const __m256d root = _mm256_sqrt_pd(l2), q = _mm256_div_pd(one, root);
  const __m256d s = _mm256_mul_pd(c, _mm256_sub_pd(inv, q));
  for (int a = 0; a < Dim; ++a)
    acc[a] = _mm256_add_pd(acc[a], _mm256_blendv_pd(minus_zero, _mm256_mul_pd(s, dx[a]), valid));
  if constexpr (Energy)
    energy =
        _mm256_add_pd(energy, _mm256_blendv_pd(minus_zero, energy_of_entries(root, c, inv), valid));
  return broken;
}

template <int Dim, bool Fracture, bool Energy>
std::int64_t row_avx2(std::int64_t i, const Fields& x, const RowArrays& r, const Breaking& w) {
  // Everything the loop reads, in locals: nothing it calls can change them, and no address of an
  // accumulator escapes the loop, so they stay in registers.
  const double* points = x.points;
  const std::int32_t* other = r.other;
  const std::int32_t* length_index = r.length_index;
  const double* inverse_lengths = r.inverse_lengths;
  const float* stiffness = r.stiffness;
  const __m256d scale = _mm256_set1_pd(r.scale), one = _mm256_set1_pd(1.0);
  // Watching, the fast test is against the lower watch limit; the slow path then sorts out the
  // breaks (at the row's own limit) and the watch.
  const double break_limit = r.break_ratio2[i];
  const bool watching = Fracture && w.watch.hit != nullptr;
  const __m256d breaking = _mm256_set1_pd(break_limit);
  const __m256d limit =
      watching ? _mm256_set1_pd(std::min(break_limit, w.watch.limit_ratio2[i])) : breaking;
  bool seen = false;
  __m256d yi[Dim], acc[Dim], energy = _mm256_setzero_pd();
  for (int a = 0; a < Dim; ++a) yi[a] = _mm256_set1_pd(x.y[a][i]), acc[a] = _mm256_setzero_pd();
  std::int64_t broken = 0;
  const std::int64_t begin = r.start[i], end = begin + r.count[i];
  const std::int64_t blocks_end = begin + ((end - begin) & ~std::int64_t{3});
  for (std::int64_t k = begin; k < blocks_end; k += 4) {
    __m256d y[4];  // the four neighbours' y_0, y_1, y_2 and V, one register each
    neighbours(points, other + k, y);
    __m256d dx[Dim], l2 = _mm256_setzero_pd();
    for (int a = 0; a < Dim; ++a) {
      dx[a] = _mm256_sub_pd(y[a], yi[a]);
      l2 = _mm256_add_pd(l2, _mm256_mul_pd(dx[a], dx[a]));
    }
    const __m256d inv = inverse_lengths_of(inverse_lengths, length_index + k);
    if constexpr (Fracture) {
      const __m256d ratio2 = _mm256_mul_pd(_mm256_mul_pd(l2, inv), inv);
      const __m256d over = _mm256_cmp_pd(ratio2, limit, _CMP_GE_OQ);
      if (_mm256_movemask_pd(over)) [[unlikely]] {
        const __m256d breaks = watching ? _mm256_cmp_pd(ratio2, breaking, _CMP_GE_OQ) : over;
        const int hit = _mm256_movemask_pd(_mm256_and_pd(breaks, intact_lanes(r, k)));
        if (hit || (watching && !seen)) {
          alignas(32) double ratios[4];
          _mm256_store_pd(ratios, ratio2);
          if (hit) broken += break_block(i, k, hit, ratios, w);
          if (watching && !seen) seen = watched(i, k, 4, ratios, r, w);
        }
      }
    }
    const __m256d root = _mm256_sqrt_pd(l2), q = _mm256_div_pd(one, root);
    // c = (K scale) V: read after the break test, which may have changed K (coefficient_of).
    const __m256d c =
        _mm256_mul_pd(_mm256_mul_pd(_mm256_cvtps_pd(_mm_loadu_ps(stiffness + k)), scale), y[3]);
    const __m256d s = _mm256_mul_pd(c, _mm256_sub_pd(inv, q));
    for (int a = 0; a < Dim; ++a) acc[a] = _mm256_add_pd(acc[a], _mm256_mul_pd(s, dx[a]));
    if constexpr (Energy) energy = _mm256_add_pd(energy, energy_of_entries(root, c, inv));
  }
  __m256d sums[Dim], energy_sums = energy;
  for (int a = 0; a < Dim; ++a) sums[a] = acc[a];
  if (end > blocks_end)
    broken += tail_avx2<Dim, Fracture, Energy>(i, blocks_end, static_cast<int>(end - blocks_end),
                                               yi, x, r, w, sums, energy_sums, seen);
  alignas(32) double lanes[Dim][4], energy_lanes[4];
  for (int a = 0; a < Dim; ++a) _mm256_store_pd(lanes[a], sums[a]);
  _mm256_store_pd(energy_lanes, energy_sums);
  write_force<Dim, Energy>(i, x, lanes, energy_lanes);
  if (watching) w.watch.hit[i] = seen ? 1 : 0;
  return broken;
}
template <int Dim>
double energy_avx2(std::int64_t i, const double* const y[3], const RowArrays& r) {
  __m256d yi[Dim];
  for (int a = 0; a < Dim; ++a) yi[a] = _mm256_set1_pd(y[a][i]);
  const __m256d zero = _mm256_setzero_pd();
  __m256d acc = zero;
  const std::int64_t begin = r.start[i], end = begin + r.count[i];
  const std::int64_t blocks_end = begin + ((end - begin) & ~std::int64_t{3});
  for (std::int64_t k = begin; k < blocks_end; k += 4) {
    const std::int32_t* j = r.other + k;
    __m256d l2 = zero;
    for (int a = 0; a < Dim; ++a) {
      const double* ya = y[a];
      const __m256d d = _mm256_sub_pd(_mm256_set_pd(ya[j[3]], ya[j[2]], ya[j[1]], ya[j[0]]), yi[a]);
      l2 = _mm256_add_pd(l2, _mm256_mul_pd(d, d));
    }
    const double* V = r.volume;
    const __m256d c = coefficients(r, k, _mm256_set_pd(V[j[3]], V[j[2]], V[j[1]], V[j[0]]));
    const __m256d inv = inverse_lengths_of(r.inverse_lengths, r.length_index + k);
    acc = _mm256_add_pd(acc, energy_of_entries(_mm256_sqrt_pd(l2), c, inv));
  }
  alignas(32) double lane[4];
  _mm256_store_pd(lane, acc);
  return energy_plain_from<Dim>(i, blocks_end, y, r, lane);
}
#pragma GCC pop_options
#endif

}  // namespace

void pack_points(const ParticleStore& p, std::vector<double>& out) {
  const auto n = static_cast<std::int64_t>(p.size());
  out.resize(4 * p.size());
  double* o = out.data();
#pragma omp parallel for schedule(static) if (n >= kParallelMinParticles)
  for (std::int64_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) o[4 * i + a] = a < p.dim() ? p.position[a][i] : 0.0;
    o[4 * i + 3] = p.volume[i];
  }
}

bool avx2_available() {
#ifdef DHPD_HAS_AVX2_BUILD
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

template <int Dim, bool Fracture, bool Energy>
RowKernel row_kernel(Build build) {
#ifdef DHPD_HAS_AVX2_BUILD
  if (build == Build::Avx2 && avx2_available()) return row_avx2<Dim, Fracture, Energy>;
#endif
  (void)build;
  return row_plain<Dim, Fracture, Energy>;
}

template <int Dim>
RowEnergy row_energy_kernel(Build build) {
#ifdef DHPD_HAS_AVX2_BUILD
  if (build == Build::Avx2 && avx2_available()) return energy_avx2<Dim>;
#endif
  (void)build;
  return energy_plain<Dim>;
}

template RowEnergy row_energy_kernel<1>(Build);
template RowEnergy row_energy_kernel<2>(Build);
template RowEnergy row_energy_kernel<3>(Build);
template RowKernel row_kernel<1, false, false>(Build);
template RowKernel row_kernel<1, false, true>(Build);
template RowKernel row_kernel<1, true, false>(Build);
template RowKernel row_kernel<1, true, true>(Build);
template RowKernel row_kernel<2, false, false>(Build);
template RowKernel row_kernel<2, false, true>(Build);
template RowKernel row_kernel<2, true, false>(Build);
template RowKernel row_kernel<2, true, true>(Build);
template RowKernel row_kernel<3, false, false>(Build);
template RowKernel row_kernel<3, false, true>(Build);
template RowKernel row_kernel<3, true, false>(Build);
template RowKernel row_kernel<3, true, true>(Build);

}  // namespace dhpd::kernel
