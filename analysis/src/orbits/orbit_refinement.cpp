// Orbit refinement (see the header): candidate periods from near returns (Lathrop and Kostelich,
// Phys. Rev. A 40 (1989) 4028), Newton on the stroboscopic map (Parker and Chua 1989, ch. 5), and
// the approach rate from the orbit's leading Floquet multiplier.
#include "pwl/orbits/orbit_refinement.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace pwl::orbits {

bool RefinementOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (max_period < 1) {
    *why = fmt::format("max period = {} must be >= 1", max_period);
    return false;
  }
  if (candidates < 1) {
    *why = fmt::format("candidates = {} must be >= 1", candidates);
    return false;
  }
  if (max_check_periods < 1) {
    *why = fmt::format("max check periods = {} must be >= 1", max_check_periods);
    return false;
  }
  if (!(on_orbit_tolerance > 0) || !std::isfinite(on_orbit_tolerance)) {
    *why = fmt::format("on-orbit tolerance = {} must be positive and finite", on_orbit_tolerance);
    return false;
  }
  for (int k : periods) {
    if (k < 1 || k > max_period) {
      *why = fmt::format("period {} to try must be in 1..max period = {}", k, max_period);
      return false;
    }
  }
  ShootingOptions shooting_check = shooting;
  shooting_check.period = 1;
  return shooting_check.is_valid(why);
}

namespace {

double inf_norm(const Vector& v) { return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>(); }

}  // namespace

std::vector<int> candidate_periods(const std::vector<Vector>& points, int max_period, int count) {
  const int N = static_cast<int>(points.size());
  if (N < 3 || max_period < 1 || count < 1) return {1};
  Vector low = points.front(), high = points.front();
  for (const Vector& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const double spread = (high - low).maxCoeff();
  if (!(spread > 0) || !std::isfinite(spread)) return {1};
  // score(k): mean |p_i − p_{i−k}|_∞ / spread over the last min(N − k, 50) points.
  const int longest = std::min(max_period, N - 1);
  std::vector<double> score(static_cast<std::size_t>(longest) + 2,
                            std::numeric_limits<double>::infinity());
  for (int k = 1; k <= longest; ++k) {
    const int m = std::min(N - k, 50);
    double sum = 0;
    for (int i = N - m; i < N; ++i) sum += inf_norm(points[i] - points[i - k]);
    score[static_cast<std::size_t>(k)] = sum / (m * spread);
  }
  // Local minima (k = 1 compares with k = 2 only), smallest score first.
  std::vector<std::pair<double, int>> minima;
  for (int k = 1; k <= longest; ++k) {
    const double s = score[static_cast<std::size_t>(k)];
    const bool left = k == 1 || s <= score[static_cast<std::size_t>(k - 1)];
    const bool right = s <= score[static_cast<std::size_t>(k + 1)];
    if (left && right) minima.emplace_back(s, k);
  }
  std::sort(minima.begin(), minima.end());
  std::vector<int> chosen;
  for (const auto& [s, k] : minima) {
    if (static_cast<int>(chosen.size()) == count) break;
    // A period-p record returns at every multiple of p, and a multiple may happen to score lower
    // (a slow drift that comes back in phase): each minimum stands for its shortest divisor whose
    // return is nearly as close.
    int d = k;
    for (int j = 1; j < k; ++j) {
      if (k % j == 0 && score[static_cast<std::size_t>(j)] <= 10 * s + 1e-3) {
        d = j;
        break;
      }
    }
    // A multiple of a period chosen already (with a closer return) adds nothing: Newton for it
    // finds the same orbits, reduced to their least period. A divisor is kept: its Newton is
    // cheaper and converges from farther out, and a period-j orbit that does not describe the
    // motion does not stop the search (refine_orbit goes on to the next candidate).
    const bool multiple =
        std::any_of(chosen.begin(), chosen.end(), [d](int c) { return d % c == 0; });
    if (!multiple) chosen.push_back(d);
  }
  std::sort(chosen.begin(), chosen.end());  // shortest first: the cheapest Newton
  if (chosen.empty()) chosen.push_back(1);
  return chosen;
}

namespace {

// Steps 3 and 4 for the orbit in r: where the motion is with respect to it.
void assess(StroboscopicMap& map, const Vector& last_state, const RefinementOptions& options,
            OrbitRefinement& r) {
  // The orbit's k points at phase 0, and the one nearest the motion (its phase on the orbit).
  const int k = r.orbit.period;
  std::vector<Vector> orbit_points{r.orbit.state};
  for (int j = 1; j < k; ++j) orbit_points.push_back(map.advance(orbit_points.back(), 1));
  int phase = 0;
  r.distance = inf_norm(last_state - orbit_points[0]);
  for (int j = 1; j < k; ++j) {
    const double d = inf_norm(last_state - orbit_points[static_cast<std::size_t>(j)]);
    if (d < r.distance) {
      r.distance = d;
      phase = j;
    }
  }
  r.tolerance = options.on_orbit_tolerance * std::max(1.0, inf_norm(r.orbit.state));
  r.on_orbit = r.distance <= r.tolerance;
  const FloquetMultipliers& mu = r.orbit.multipliers;
  r.attracting = mu.converged && mu.stable();
  const double rho = mu.largest_modulus();
  r.contraction_per_period = rho > 0 ? std::pow(rho, 1.0 / k) : 0.0;
  r.periods_to_settle = 0;
  r.check_periods = 0;
  r.measured_factor = r.predicted_factor = 0;
  r.approach_confirmed = false;
  if (!r.attracting || r.on_orbit) return;
  r.periods_to_settle = rho > 0 ? k * std::log(r.tolerance / r.distance) / std::log(rho) : k;
  // Step 4: carry the motion on for P + W periods (P: the multiplier halves the distance in P
  // periods; W = P/4, at least one period) and compare the largest distance over the last W
  // periods with the largest over the first W, which the multiplier predicts to be half of it.
  // Window maxima, not single distances: on a torus or another attractor around the orbit the
  // distance rises and falls along the motion, and one sample can fall low by chance.
  const double halving = rho > 0 ? k * std::log(0.5) / std::log(rho) : 1.0;
  const double limit = static_cast<double>(options.max_check_periods);
  const int window = static_cast<int>(std::clamp(std::ceil(halving / 4), 1.0, limit / 5));
  r.check_periods = static_cast<int>(std::clamp(std::ceil(halving), 1.0, limit - window)) + window;
  r.predicted_factor = std::pow(rho, static_cast<double>(r.check_periods - window) / k);
  try {
    Vector motion = last_state;
    double first = r.distance, last = 0.0;
    for (int i = 1; i <= r.check_periods; ++i) {
      motion = map.advance(motion, 1);
      const double d = inf_norm(
          motion - orbit_points[static_cast<std::size_t>((phase + i) % k)]);
      if (i < window) first = std::max(first, d);
      if (i > r.check_periods - window) last = std::max(last, d);
    }
    r.measured_factor = last / first;
    // Only an approach that halves within the check can be confirmed: a slower one (a leading
    // multiplier so close to the unit circle that the budget holds less than a halving) predicts a
    // change the rise and fall of a motion on a torus around the orbit can mimic.
    r.approach_confirmed = r.predicted_factor <= 0.5 &&
                           r.measured_factor <= std::sqrt(r.predicted_factor);
  } catch (const DivergenceError&) {
    r.approach_confirmed = false;
  }
}

}  // namespace

OrbitRefinement refine_orbit(StroboscopicMap& map, const std::vector<Vector>& points,
                             const Vector& last_state, const RefinementOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (last_state.size() != map.state_size()) {
    throw InputError(fmt::format("last state has {} components, the state {}", last_state.size(),
                                 map.state_size()));
  }
  if (!last_state.allFinite()) throw InputError("last state is not finite");

  // Every candidate in turn until an orbit explains the motion; otherwise the first orbit found.
  OrbitRefinement r, first;
  const std::vector<int> periods =
      options.periods.empty() ? candidate_periods(points, options.max_period, options.candidates)
                              : options.periods;
  for (int k : periods) {
    r.tried.push_back(k);
    ShootingOptions shooting = options.shooting;
    shooting.period = k;
    shooting.multipliers = true;
    try {
      // Reduced to its least period (at_minimal_period).
      r.orbit = at_minimal_period(map, find_periodic_orbit(map, last_state, shooting), shooting);
      r.found = true;
      assess(map, last_state, options, r);
      if (r.explains_motion()) return r;
      if (!first.found) first = r;
    } catch (const ShootingError& e) {
      r.failure = e.what();
    } catch (const DivergenceError& e) {
      r.failure = e.what();
    }
  }
  if (first.found) {
    first.tried = r.tried;
    return first;
  }
  if (r.failure.empty()) r.failure = "no candidate period";
  return r;
}

std::string OrbitRefinement::describe() const {
  if (!found) return fmt::format("no orbit found (periods tried: {}; {})", fmt::join(tried, ", "),
                                 failure);
  const std::string name = fmt::format("period-{}", orbit.period);
  const std::string rate = fmt::format("|μ| = {:.6g} per period", contraction_per_period);
  if (on_orbit) {
    return fmt::format("{}, {} ({}): the motion is on it (distance {:.1e})", name,
                       attracting ? "attracting" : "not attracting", rate, distance);
  }
  if (attracting && approach_confirmed) {
    return fmt::format("{}, attracting ({}): the motion approaches it, {:.1e} away, reached after "
                       "about {:.0f} more periods",
                       name, rate, distance, std::ceil(periods_to_settle));
  }
  if (attracting) {
    return fmt::format("{}, attracting ({}), {:.1e} away, but the motion does not approach it as "
                       "predicted (its distance changed by {:.3g} in {} periods, predicted {:.3g}): "
                       "it does not describe the motion",
                       name, rate, distance, measured_factor, check_periods, predicted_factor);
  }
  if (!orbit.multipliers.converged) {
    return fmt::format("{}, stability undetermined (Arnoldi did not converge; {}), {:.1e} away",
                       name, rate, distance);
  }
  return fmt::format("{}, unstable ({}), {:.1e} away: it does not describe the motion", name,
                     rate, distance);
}

}  // namespace pwl::orbits
