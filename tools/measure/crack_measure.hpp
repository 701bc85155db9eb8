// Crack measurements from the damage field: tip, speed, angle, branching (IJNME 2016 eq. 59–60;
// docs/theory.md §15). Pure functions of the particle store; no VTK, no CGAL.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/discretization/particles.hpp"
#include "engine/physics/material_law.hpp"
#include "geometry/shapes.hpp"
#include "geometry/vec.hpp"
#include "tools/measure/damage_graph.hpp"

namespace dhpd::measure {

using geometry::Vec3;

/// A notch tip to follow: where the crack starts and the direction of the notch.
struct Tip {
  std::string name;
  Vec3 at{0, 0, 0};
  Vec3 direction{1, 0, 0};  ///< non-zero, need not be unit
  /// 3D: the notch front's direction. Damage apart only along the front (e.g. at the two faces
  /// of a plate, ahead of the middle) is one crack front, not two branches.
  std::optional<Vec3> front;
  /// Only damage inside this shape belongs to the tip's crack (two notches whose cracks would
  /// join through damage between them: an impact zone, a spall crack).
  std::optional<geometry::Shape> region;
};

/// How far (in horizons of the crack tip) a crack has run when its initial angle is taken.
inline constexpr double kInitialHorizons = 3.0;

/// The `measure` block of a scene (docs/scenes.md, `measure`).
struct Settings {
  double damage_threshold = 0.35;  ///< φ ≥ this counts as cracked
  std::int64_t every = 10;         ///< steps between measurements
  std::int64_t smoothing = 1;      ///< speed over this many measurement intervals (eq. 59: 1)
  double branch_separation = 2.0;  ///< distinct branches: centroids farther than this × δ
  std::vector<Tip> tips;
};

/// Published reference values echoed into summary.json: a number, a list of numbers, or a map of
/// such values (keys in the order given).
struct Published {
  enum class Kind { Number, List, Map };
  Kind kind = Kind::Map;
  double number = 0.0;
  bool integer = false;  ///< the number was written as an integer (echoed as one)
  std::vector<double> list;
  std::vector<std::string> keys;
  std::vector<Published> values;
};

/// One tip at one measurement: a row of cracks.csv.
struct TipRow {
  std::int64_t step = 0;
  double time = 0.0;
  std::size_t tip = 0;    ///< index into Settings::tips
  Vec3 x{0, 0, 0};        ///< crack tip, reference position (the notch tip while nothing cracked)
  double distance = 0.0;  ///< |x − notch tip|
  double path_length = 0.0;  ///< shortest path through the crack from the notch tip to x
  double speed = 0.0;        ///< eq. 59 over `smoothing` intervals (0 at the first measurement)
  double angle_deg = 0.0;    ///< between the notch direction and x − notch tip; NaN at distance 0
  int branches = 0;          ///< separated clusters (1 for a single crack, 0 when none)
};

/// What a run reports for one tip (summary.json "cracks").
struct CrackSummary {
  std::string name;
  std::optional<double> initiation_time;  ///< first time a crack (φ ≥ threshold) meets the notch
  std::optional<double> angle_deg;        ///< at the last measurement
  std::optional<double> max_speed;        ///< largest speed over intervals once the crack runs
  std::optional<double> mean_speed;       ///< path advanced since it runs / time since then
  std::vector<double> branch_times;
  std::vector<double> branch_speeds;   ///< the tip's speed (eq. 59, smoothed) at each branching
  std::vector<Vec3> branch_positions;  ///< the centroids of the clusters at each new branching
  /// The crack's angle once its tip is kInitialHorizons horizons from the notch tip (the angle the
  /// papers quote for where a crack leaves the notch); `angle_deg` is the chord to the last tip.
  std::optional<double> initial_angle_deg;
  int most_branches = 0;  ///< the largest branch count of any measurement
  Vec3 tip{0, 0, 0};
};

/// The crack of one tip: the nodes reached from the particles within one horizon of the notch
/// tip, with their path distance (seeded with the straight distance), and the farthest of them.
/// With a `region`, only nodes inside it take part.
struct CrackPath {
  std::vector<double> path;  ///< per node of the graph; +inf when not in this crack
  std::int32_t tip = -1;     ///< node farthest along the path, −1 when the crack is empty
};
CrackPath crack_path(const DamageGraph& g, const ParticleStore& p, const Vec3& notch_tip,
                     const geometry::Shape* region = nullptr);

/// Branches of a crack: its nodes binned by path distance in bins one horizon wide (the largest
/// horizon of the crack), clusters of linked nodes within a bin, and the largest number of
/// clusters of one bin whose centroids are pairwise farther apart than `separation` × the largest
/// horizon of that bin. `centroids` are those clusters' (of the first bin with the most).
struct Branches {
  int count = 0;
  std::vector<Vec3> centroids;
};
Branches count_branches(const DamageGraph& g, const CrackPath& crack, const ParticleStore& p,
                        double separation, const std::optional<Vec3>& front = std::nullopt);

/// Follows every tip over the measurements of a run. It keeps no particle index between
/// measurements, so the store may change (refinement) from one to the next.
class CrackTracker {
 public:
  explicit CrackTracker(Settings settings);

  const Settings& settings() const { return s_; }
  /// Whether step k is a measurement step (every `every` steps, from step 0).
  bool due(std::int64_t step) const { return step % s_.every == 0; }
  /// Measures every tip on the current damage of `p` (φ must be up to date); one row per tip.
  /// With the store's `revision`, the damage graph grows from the last measurement of the same
  /// revision (GrowingDamageGraph); without, it is built anew. The rows are the same either way.
  /// `damage` (with a revision only): the particles' damage when not p.damage, e.g. a copy taken
  /// at `step` while the run has gone on (p's other fields must still be those of `step`).
  std::vector<TipRow> measure(const ParticleStore& p, std::int64_t step, double time,
                              const std::optional<Revision>& revision = std::nullopt,
                              const double* damage = nullptr);
  /// One entry per tip, in the order of Settings::tips.
  std::vector<CrackSummary> summary() const;

  /// Archives what the tracker has measured so far (checkpoints): `Self` is CrackTracker when
  /// reading, const CrackTracker when writing. Returns false when what was read does not fit
  /// the tracker's tips.
  template <class Self, class Archive>
  static bool archive_state(Self& self, Archive& ar) {
    std::uint64_t tracks = self.tracks_.size();
    ar(tracks);
    if (tracks != self.tracks_.size()) return false;
    for (auto& t : self.tracks_) {
      ar(t.time), ar(t.x), ar(t.path), ar(t.initiated), ar(t.running), ar(t.max_speed);
      ar(t.angle_deg), ar(t.most_branches), ar(t.branch_times), ar(t.branch_positions);
      ar(t.branch_speeds), ar(t.initial_angle);
      const auto n = t.time.size();
      if (t.x.size() != n || t.path.size() != n || (t.initiated && *t.initiated >= n) ||
          (t.running && *t.running >= n))
        return false;
    }
    return true;
  }

 private:
  struct Track {
    std::vector<double> time;
    std::vector<Vec3> x;
    std::vector<double> path;
    std::optional<std::size_t> initiated;  ///< first measurement with a crack at the notch
    std::optional<std::size_t> running;    ///< first measurement with the tip > one horizon out
    std::optional<double> max_speed;
    std::optional<double> angle_deg;
    int most_branches = 0;
    std::vector<double> branch_times;
    std::vector<Vec3> branch_positions;
    std::vector<double> branch_speeds;    ///< the tip's speed where each branching was found
    std::optional<double> initial_angle;  ///< chord angle once the tip is kInitialHorizons out
  };
  /// A tip's crack path and branches on one version of the grown graph (a cache: not archived).
  struct CrackShape {
    std::optional<std::uint64_t> graph_version;
    CrackPath crack;
    Branches branches;
  };
  /// `graph_version`: the grown graph's version when `g` is it (its shape is then reused while
  /// the graph stays), nullopt for a graph built for this measurement.
  TipRow measure_tip(const DamageGraph& g, const ParticleStore& p, std::size_t k, std::int64_t step,
                     double time, std::optional<std::uint64_t> graph_version);
  const CrackShape& shape_of(const DamageGraph& g, const ParticleStore& p, std::size_t k,
                             std::optional<std::uint64_t> graph_version);

  Settings s_;
  std::vector<Track> tracks_;
  GrowingDamageGraph graph_{s_.damage_threshold};  ///< a cache: not archived
  std::vector<CrackShape> shapes_;                 ///< per tip
};

/// Rayleigh speed (IJNME 2016 eq. 60) of the material of the particle nearest `at`.
double rayleigh_speed_near(const ParticleStore& p, const std::vector<Material>& materials,
                           const Section& section, const Vec3& at);

/// Unsigned angle in degrees between two non-zero vectors (NaN when one is zero).
double angle_between_deg(const Vec3& a, const Vec3& b);

}  // namespace dhpd::measure
