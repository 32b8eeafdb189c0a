#pragma once
// What a periodic orbit does between its Poincaré points: the extremes of every displacement (the
// amplitude a frequency-response curve plots) and of every gap function g_j = w_j^T x − Δ_j (its
// largest value says whether spring j touches along the orbit; where it passes through zero as a
// parameter moves, a contact appears or disappears: a grazing bifurcation).
//
// The motion is sampled along the orbit (every step of a fixed-grid method; `samples_per_period`
// points of any other), and each sample interval is interpolated by the cubic Hermite polynomial
// of the values and their exact derivatives (x' is part of the state, g' = w^T x'), whose extremes
// are found in closed form: an error of O(h⁴). With a method that stops anywhere (the exact
// solver) the extremes of the gap functions are then refined to rounding by bisection on g' = 0.
#include "pwl/orbits/stroboscopic_map.hpp"

namespace pwl::orbits {

struct OrbitProfile {
  Vector max_position;  // per degree of freedom, over the orbit
  Vector min_position;
  Vector amplitude;     // max |x_i(t)|
  Vector max_gap;       // per gap spring: max over the orbit of g_j (> 0: it touches)
  Vector min_gap;       // min over the orbit of g_j (> 0: it never lets go)
  Vector max_gap_time;  // where each extreme lies: t in [0, kT] from the orbit's start
  Vector min_gap_time;
};

// The profile of the orbit through `state` over `periods` forcing periods from t = 0.
// samples_per_period applies to methods off a fixed grid (>= 8).
OrbitProfile orbit_profile(StroboscopicMap& map, const Vector& state, int periods,
                           int samples_per_period = 256);

// One extreme of one gap function along the orbit (the largest when `largest`, else the
// smallest), found as orbit_profile finds it, and its time t in [0, kT]: where only one is wanted
// (a grazing curve's condition), without the others' refinements.
struct GapExtreme {
  double value = 0.0;
  double time = 0.0;
};
GapExtreme gap_extreme(StroboscopicMap& map, const Vector& state, int periods, int spring,
                       bool largest, int samples_per_period = 256);

}  // namespace pwl::orbits
