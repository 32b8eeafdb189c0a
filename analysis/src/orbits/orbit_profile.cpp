#include "pwl/orbits/orbit_profile.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <vector>

#include "pwl/errors.hpp"

namespace pwl::orbits {

namespace {

// A spring's direction w (g = wᵀx − Δ) kept sparse: it touches one or two degrees of freedom, so
// that the gap functions of 10^4 springs along an orbit cost O(springs · samples), not times n.
using Direction = Eigen::SparseVector<double>;

struct Sample {
  double t;
  Vector x, v;
};

// The extremes over [0, 1] of the cubic Hermite interpolant of q with q(0) = qa, q(1) = qb and
// derivatives (in s) da, db; updates lo and hi, and where given, the s at which each is taken.
void hermite_extremes(double qa, double da, double qb, double db, double& lo, double& hi,
                      double* lo_at = nullptr, double* hi_at = nullptr) {
  const double a = 2 * (qa - qb) + da + db;
  const double b = 3 * (qb - qa) - 2 * da - db;
  const double c = da;
  const auto value = [&](double s) { return ((a * s + b) * s + c) * s + qa; };
  const auto keep = [&](double q, double s) {
    if (q < lo) {
      lo = q;
      if (lo_at != nullptr) *lo_at = s;
    }
    if (q > hi) {
      hi = q;
      if (hi_at != nullptr) *hi_at = s;
    }
  };
  const auto take = [&](double s) {
    if (s > 0 && s < 1) keep(value(s), s);
  };
  keep(qa, 0.0);
  keep(qb, 1.0);
  // q'(s) = 3a s² + 2b s + c
  if (std::abs(a) < 1e-300) {
    if (b != 0) take(-c / (2 * b));
    return;
  }
  const double disc = b * b - 3 * a * c;
  if (disc < 0) return;
  const double root = std::sqrt(disc);
  take((-b + root) / (3 * a));
  take((-b - root) / (3 * a));
}

// The motion along the orbit through `state`: every step of a fixed-grid method, or
// `samples_per_period` points a period of any other.
std::vector<Sample> sample_orbit(StroboscopicMap& map, const Vector& state, int periods,
                                 int samples_per_period) {
  if (periods < 1) throw InputError(fmt::format("periods = {} must be >= 1", periods));
  if (samples_per_period < 8) {
    throw InputError(fmt::format("samples per period = {} must be >= 8", samples_per_period));
  }
  const Index n = map.dofs();
  if (state.size() != 2 * n || !state.allFinite()) {
    throw InputError(fmt::format("orbit state has {} components (needs {} finite ones)",
                                 state.size(), 2 * n));
  }
  Integrator& integrator = map.integrator();
  const double T = map.forcing_period();
  const bool on_grid = method_traits(map.settings().method).fixed_grid;
  std::vector<Sample> samples;
  integrator.set_state(0.0, state.head(n), state.tail(n));
  samples.push_back({0.0, state.head(n), state.tail(n)});
  if (on_grid) {
    integrator.advance_to(periods * T, [&](double t, const Vector& x, const Vector& v) {
      samples.push_back({t, x, v});
    });
  } else {
    const long count = static_cast<long>(periods) * samples_per_period;
    for (long i = 1; i <= count; ++i) {
      integrator.advance_to(static_cast<double>(i) * periods * T / static_cast<double>(count));
      samples.push_back({integrator.time(), integrator.position(), integrator.velocity()});
    }
  }
  return samples;
}

// The extreme (the largest when `maximum`, else the smallest) of the gap function w^T x − gap on
// the cubic Hermite interpolant of the samples: its value, its time, and its sample interval.
struct Interpolated {
  double value, time;
  std::size_t at;
};
Interpolated interpolated_extreme(const std::vector<Sample>& samples, const Direction& w, double gap,
                                  bool maximum) {
  const double inf = std::numeric_limits<double>::infinity();
  Interpolated best{maximum ? -inf : inf, 0.0, 0};
  for (std::size_t s = 0; s + 1 < samples.size(); ++s) {
    const Sample& A = samples[s];
    const Sample& B = samples[s + 1];
    const double h = B.t - A.t;
    if (!(h > 0)) continue;
    double lo = inf, hi = -inf, lo_s = 0.0, hi_s = 0.0;
    hermite_extremes(w.dot(A.x) - gap, h * w.dot(A.v), w.dot(B.x) - gap, h * w.dot(B.v), lo, hi,
                     &lo_s, &hi_s);
    if (maximum && hi > best.value) best = {hi, A.t + hi_s * h, s};
    if (!maximum && lo < best.value) best = {lo, A.t + lo_s * h, s};
  }
  return best;
}

// The extreme refined on the exact motion (a method that stops anywhere): bisection on the sign of
// g' over its sample interval and its neighbours, where the extreme may sit at a sample. Keeps
// `extreme` where no interior extreme of the kind is found.
void refine_extreme(Integrator& integrator, const std::vector<Sample>& samples, const Direction& w,
                    double gap, bool maximum, std::size_t s, double& value, double& time) {
  const double inf = std::numeric_limits<double>::infinity();
  bool found = false;
  double best = maximum ? -inf : inf;
  double best_t = 0.0;
  const auto better = [&](double g, double t) {
    if (maximum ? g > best : g < best) {
      best = g;
      best_t = t;
    }
  };
  const std::size_t first = s == 0 ? 0 : s - 1;
  const std::size_t last = std::min(samples.size() - 2, s + 1);
  for (std::size_t k = first; k <= last; ++k) {
    const Sample& A = samples[k];
    const Sample& B = samples[k + 1];
    const double sign = maximum ? 1.0 : -1.0;
    const double da = sign * w.dot(A.v), db = sign * w.dot(B.v);
    if (!(da > 0 && db < 0)) continue;  // no interior extreme of this kind
    double lo = A.t, hi = B.t, mid = A.t;
    Vector x = A.x, v = A.v;
    for (int it = 0; it < 60 && hi - lo > 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, hi); ++it) {
      mid = 0.5 * (lo + hi);
      integrator.set_state(A.t, A.x, A.v);
      integrator.advance_to(mid);
      x = integrator.position();
      v = integrator.velocity();
      if (sign * w.dot(v) > 0) lo = mid; else hi = mid;
    }
    better(w.dot(x) - gap, mid);
    found = true;
  }
  if (!found) return;
  // A sample itself may be the extreme (at the orbit's ends).
  for (const Sample& S : samples) better(w.dot(S.x) - gap, S.t);
  value = best;
  time = best_t;
}

}  // namespace

OrbitProfile orbit_profile(StroboscopicMap& map, const Vector& state, int periods,
                           int samples_per_period) {
  const std::vector<Sample> samples = sample_orbit(map, state, periods, samples_per_period);
  const Index n = map.dofs();
  const GapStructure& structure = map.structure();
  const SparseMatrix W = structure.spring_directions_sparse();
  const Vector gaps = structure.spring_gaps();
  const bool on_grid = method_traits(map.settings().method).fixed_grid;

  OrbitProfile profile;
  const double inf = std::numeric_limits<double>::infinity();
  profile.max_position = Vector::Constant(n, -inf);
  profile.min_position = Vector::Constant(n, inf);
  const Index springs = structure.spring_count();
  profile.max_gap = Vector::Constant(springs, -inf);
  profile.min_gap = Vector::Constant(springs, inf);
  profile.max_gap_time = Vector::Zero(springs);
  profile.min_gap_time = Vector::Zero(springs);
  for (std::size_t s = 0; s + 1 < samples.size(); ++s) {
    const Sample& A = samples[s];
    const Sample& B = samples[s + 1];
    const double h = B.t - A.t;
    if (!(h > 0)) continue;
    for (Index i = 0; i < n; ++i) {
      double lo = profile.min_position(i), hi = profile.max_position(i);
      hermite_extremes(A.x(i), h * A.v(i), B.x(i), h * B.v(i), lo, hi);
      profile.min_position(i) = lo;
      profile.max_position(i) = hi;
    }
  }
  profile.amplitude = profile.max_position.cwiseAbs().cwiseMax(profile.min_position.cwiseAbs());
  for (Index j = 0; j < springs; ++j) {
    const Direction w = W.col(j);
    for (const bool maximum : {true, false}) {
      const Interpolated e = interpolated_extreme(samples, w, gaps(j), maximum);
      double value = e.value, time = e.time;
      if (!on_grid) refine_extreme(map.integrator(), samples, w, gaps(j), maximum, e.at, value, time);
      (maximum ? profile.max_gap : profile.min_gap)(j) = value;
      (maximum ? profile.max_gap_time : profile.min_gap_time)(j) = time;
    }
  }
  return profile;
}

GapExtreme gap_extreme(StroboscopicMap& map, const Vector& state, int periods, int spring,
                       bool largest, int samples_per_period) {
  const GapStructure& structure = map.structure();
  if (spring < 0 || spring >= structure.spring_count()) {
    throw InputError(fmt::format("spring {} of {}", spring + 1, structure.spring_count()));
  }
  const std::vector<Sample> samples = sample_orbit(map, state, periods, samples_per_period);
  const Direction w = structure.spring_directions_sparse().col(spring);
  const double gap = structure.spring_gaps()(spring);
  const Interpolated e = interpolated_extreme(samples, w, gap, largest);
  GapExtreme out{e.value, e.time};
  if (!method_traits(map.settings().method).fixed_grid) {
    refine_extreme(map.integrator(), samples, w, gap, largest, e.at, out.value, out.time);
  }
  return out;
}

}  // namespace pwl::orbits
