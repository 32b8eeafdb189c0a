#pragma once
// Telling attractors apart: which of the motions started from many initial states end on the same
// attractor. A basin map (study/basin_map.hpp) classifies every initial state of a grid and needs
// to say "this cell goes to attractor 2", not only "period-1": two coexisting period-1 orbits of a
// hardening oscillator, one that reaches the gap and one that does not, are different attractors
// with the same name.
//
// Each motion is given by a tail of its stroboscopic points (full states [x; v], one per row) and
// its regime. Motions are matched, in the order they are given, against the attractors found so
// far; one that matches none starts a new attractor, whose representative is that motion's tail.
// Given in a fixed order (a basin map gives cells by id), the catalogue is the same whatever the
// order in which the motions were computed.
//
// When two tails are the same attractor:
//  - period-k (k >= 1): both are period-k, and every one of the last k points of the motion lies
//    within periodic_tolerance * scale of one of the representative's last k points, the scale
//    being the larger of the orbit's diameter and its largest |p| (so the test is relative for
//    an orbit of any size, also a period-1 point). The points of a period-k orbit are those of
//    its k phases, so the test does not care at which phase the tail stops.
//  - quasi-periodic, chaotic or uncertain (any two of them: a torus may be called quasi-periodic
//    from one initial state and uncertain from another, with a shorter settling): the two point
//    clouds cover each other. With s the median distance from a point of a cloud to its nearest
//    neighbour in the same cloud (how densely the tails sample the attractor) and c_AB the median
//    distance from a point of A to its nearest point of B, they match when c_AB and c_BA are both
//    at most cloud_factor * max(s_A, s_B). Two samples of one set are as close to each other as
//    their points are to their own neighbours; two disjoint attractors are as far apart as they
//    are, which is many spacings unless they nearly touch.
//  - unbounded: every unbounded motion is the one "attractor at infinity".
//  - failed (an unsolvable LCP, a spent work budget): no attractor (id 0).
// Periodic tails never match non-periodic ones. Two coexisting orbits closer than the tolerance,
// or two non-periodic attractors that interleave at the sampling density, are counted as one.
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::analysis {

struct AttractorMatchOptions {
  double periodic_tolerance = 1e-3;  // relative to the orbit's scale (> 0)
  double cloud_factor = 3.0;         // in nearest-neighbour spacings (> 0)
  // Ceres-style check: false with a message naming the field and the value.
  bool is_valid(std::string* why) const;
};

// One motion: its regime (as PointResult::regime: "period-3", "quasi-periodic", "chaotic",
// "uncertain", "unbounded", "failed"), its period (k for period-k, else 0) and the tail of its
// stroboscopic points, one full state a row (may be empty for unbounded or failed motions; a
// period-k motion needs at least k rows, a non-periodic one at least 2).
struct MotionTail {
  std::string regime;
  int period = 0;
  Matrix points;
};

struct Attractor {
  int id = 0;           // 1, 2, ... in the order they were found
  std::string regime;   // of the first motion that found it
  int period = 0;       // k of a period-k attractor, else 0
  Matrix points;        // the representative tail (empty for the attractor at infinity)
  long motions = 0;     // motions matched to it, the first included
  long first = -1;      // the caller's tag of its first motion (a basin map: the cell id)
  // "period-2", "quasi-periodic", "unbounded": the name of its first motion.
  std::string name() const { return regime; }
};

class AttractorCatalogue {
 public:
  // Throws InputError for invalid options.
  explicit AttractorCatalogue(const AttractorMatchOptions& options = {});

  // The id of the attractor `motion` ends on: an existing one it matches, or a new one it founds
  // (its representative is this tail, its first tag `tag`); 0 for a failed motion. Throws
  // InputError for a tail that is too short for its regime, or whose width differs from the
  // catalogue's.
  int match(const MotionTail& motion, long tag = -1);

  const std::vector<Attractor>& attractors() const { return attractors_; }
  // The attractor of id `id` (1-based). Throws InputError when there is none.
  const Attractor& attractor(int id) const;

 private:
  bool same_orbit(const Attractor& a, const MotionTail& motion) const;
  bool same_cloud(const Attractor& a, const MotionTail& motion) const;

  AttractorMatchOptions options_;
  std::vector<Attractor> attractors_;
  Index width_ = -1;  // columns of every tail, once one is seen
};

// Whether a regime name is period-k (k from the PointResult) or one of the non-periodic bounded
// regimes the cloud test compares.
bool is_periodic_regime(const std::string& regime);
bool is_bounded_aperiodic_regime(const std::string& regime);

}  // namespace pwl::analysis
