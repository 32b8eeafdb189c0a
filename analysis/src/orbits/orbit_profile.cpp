#include "pwl/orbits/orbit_profile.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <vector>

#include "pwl/errors.hpp"

namespace pwl::orbits {

namespace {

struct Sample {
  double t;
  Vector x, v;
};

// The extremes over [0, 1] of the cubic Hermite interpolant of q with q(0) = qa, q(1) = qb and
// derivatives (in s) da, db; updates lo and hi.
void hermite_extremes(double qa, double da, double qb, double db, double& lo, double& hi) {
  const double a = 2 * (qa - qb) + da + db;
  const double b = 3 * (qb - qa) - 2 * da - db;
  const double c = da;
  const auto value = [&](double s) { return ((a * s + b) * s + c) * s + qa; };
  const auto take = [&](double s) {
    if (s > 0 && s < 1) {
      const double q = value(s);
      lo = std::min(lo, q);
      hi = std::max(hi, q);
    }
  };
  lo = std::min({lo, qa, qb});
  hi = std::max({hi, qa, qb});
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

}  // namespace

OrbitProfile orbit_profile(StroboscopicMap& map, const Vector& state, int periods,
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
  const GapStructure& structure = map.structure();
  const Matrix W = structure.spring_directions();
  const Vector gaps = structure.spring_gaps();
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

  OrbitProfile profile;
  const double inf = std::numeric_limits<double>::infinity();
  profile.max_position = Vector::Constant(n, -inf);
  profile.min_position = Vector::Constant(n, inf);
  const Index springs = structure.spring_count();
  profile.max_gap = Vector::Constant(springs, -inf);
  profile.min_gap = Vector::Constant(springs, inf);
  // Where each gap's extremes lie: the sample interval, to refine.
  std::vector<std::size_t> max_at(springs, 0), min_at(springs, 0);
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
    if (springs == 0) continue;
    const Vector ga = W.transpose() * A.x - gaps, gb = W.transpose() * B.x - gaps;
    const Vector da = W.transpose() * A.v, db = W.transpose() * B.v;
    for (Index j = 0; j < springs; ++j) {
      double lo = inf, hi = -inf;
      hermite_extremes(ga(j), h * da(j), gb(j), h * db(j), lo, hi);
      if (hi > profile.max_gap(j)) {
        profile.max_gap(j) = hi;
        max_at[j] = s;
      }
      if (lo < profile.min_gap(j)) {
        profile.min_gap(j) = lo;
        min_at[j] = s;
      }
    }
  }
  profile.amplitude = profile.max_position.cwiseAbs().cwiseMax(profile.min_position.cwiseAbs());

  if (!on_grid && springs > 0) {
    // Refine each gap extreme on the exact motion: bisection on the sign of g' over the interval
    // (and its neighbours, where the extreme may sit at a sample).
    const auto refine = [&](Index j, std::size_t s, bool maximum) {
      // The exact extremes replace the interpolated ones where an interior extreme is found.
      bool found = false;
      double best = maximum ? -inf : inf;
      const std::size_t first = s == 0 ? 0 : s - 1;
      const std::size_t last = std::min(samples.size() - 2, s + 1);
      for (std::size_t k = first; k <= last; ++k) {
        const Sample& A = samples[k];
        const Sample& B = samples[k + 1];
        const double sign = maximum ? 1.0 : -1.0;
        const double da = sign * W.col(j).dot(A.v), db = sign * W.col(j).dot(B.v);
        if (!(da > 0 && db < 0)) continue;  // no interior extreme of this kind
        double lo = A.t, hi = B.t;
        Vector x = A.x, v = A.v;
        for (int it = 0; it < 60 && hi - lo > 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, hi); ++it) {
          const double mid = 0.5 * (lo + hi);
          integrator.set_state(A.t, A.x, A.v);
          integrator.advance_to(mid);
          x = integrator.position();
          v = integrator.velocity();
          if (sign * W.col(j).dot(v) > 0) lo = mid; else hi = mid;
        }
        const double g = W.col(j).dot(x) - gaps(j);
        best = maximum ? std::max(best, g) : std::min(best, g);
        found = true;
      }
      if (!found) return;
      // A sample itself may be the extreme (at the orbit's ends).
      for (const Sample& S : samples) {
        const double g = W.col(j).dot(S.x) - gaps(j);
        best = maximum ? std::max(best, g) : std::min(best, g);
      }
      if (maximum) profile.max_gap(j) = best; else profile.min_gap(j) = best;
    };
    for (Index j = 0; j < springs; ++j) {
      refine(j, max_at[j], true);
      refine(j, min_at[j], false);
    }
  }
  return profile;
}

}  // namespace pwl::orbits
