#pragma once
// Period detection on a sequence of Poincaré points.
//
// A motion is period-k on a Poincaré section when its section points repeat after k samples:
// p[n] = p[n - k] for every n past the transient. Numerically the points only repeat to within the
// accuracy of the integrator, so the comparison uses a tolerance relative to the size of the
// attractor: two points "coincide" when their distance is at most tolerance * scale, where
//
//     scale = max(diameter of the point cloud, relative_floor * largest |p|, absolute_floor).
//
// The diameter makes the test independent of units and amplitude; the two floors keep a cloud
// that has collapsed onto a single point (a fixed point, whose diameter is rounding noise) from
// being judged against its own noise. The diameter is measured as the diagonal of the axis-aligned
// bounding box of the points, which lies between the true diameter and sqrt(dim) times it and
// costs O(n) instead of O(n^2).
//
// The smallest k <= k_max is reported for which the last `cycles` periods each repeat the one
// before them, i.e. |p[n-1-j] - p[n-1-j-k]| <= tolerance * scale for j = 0 .. cycles*k - 1.
// Requiring more than one period to repeat protects against a chance near-return of a
// quasi-periodic or chaotic orbit. Testing from k = 1 upwards and stopping at the first success
// gives the least period (a period-2 orbit also repeats after 4 and 6 samples).
//
// Distances are Euclidean in the coordinates given: scale the state components (for example
// displacements and velocities) to comparable magnitudes first if they differ by orders of
// magnitude. The points should come from after the transient; the whole sequence is used for the
// scale, so a transient left in makes the test more lenient.
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::analysis {

struct PeriodOptions {
  int k_max = 64;              // largest period searched (>= 1)
  int cycles = 2;              // how many consecutive periods must repeat (>= 1)
  double tolerance = 1e-6;     // relative to scale (> 0)
  double relative_floor = 1e-3;  // scale >= relative_floor * max_n |p[n]| (>= 0)
  double absolute_floor = 1e-9;  // scale >= absolute_floor, in state units (>= 0)
  // If > 0, use this scale instead of the automatic one (for example the same scale over a whole
  // parameter grid).
  double scale = 0.0;

  // Ceres-style check: false with a message naming the field and its value.
  bool is_valid(std::string* why) const;
};

struct PeriodResult {
  // The least period found, or 0 when no k <= k_max repeats (or too few points to test any).
  int period = 0;
  // Whether the motion sits on a fixed point of the map (period == 1: each of the last `cycles`
  // points within tolerance * scale of the one before). For a stroboscopic map of a forced system
  // that is a period-1 response; for an autonomous system sampled in time it is an equilibrium.
  bool fixed_point = false;
  // Largest |p[n-1-j] - p[n-1-j-k]| / scale over the compared points for the reported period; when
  // no period was found, the smallest such value over the k that could be tested (and best_k is
  // that k). Infinity when no k could be tested.
  double mismatch = 0.0;
  int best_k = 0;
  // Number of mutually distinct points (closer than tolerance * scale counts as the same) among
  // the last `period` points when a period was found, else among the last
  // min(n, (cycles + 1) * k_max) points.
  int distinct_points = 0;
  double scale = 0.0;     // the scale used
  double diameter = 0.0;  // bounding-box diagonal of the points
  int points_used = 0;    // how many points the search compared, counting from the end
};

// Throws InputError for invalid options, an empty sequence, points of differing dimension or a
// non-finite coordinate (the message names points[i] and the value).
PeriodResult detect_period(const std::vector<Vector>& points, const PeriodOptions& options = {});

// Convenience for scalar maps (each point one number).
PeriodResult detect_period(const std::vector<double>& values, const PeriodOptions& options = {});

}  // namespace pwl::analysis
