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
  if (!(on_orbit_tolerance > 0) || !std::isfinite(on_orbit_tolerance)) {
    *why = fmt::format("on-orbit tolerance = {} must be positive and finite", on_orbit_tolerance);
    return false;
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
    const bool multiple =
        std::any_of(chosen.begin(), chosen.end(), [d](int c) { return d % c == 0; });
    if (!multiple) chosen.push_back(d);
  }
  // Shortest first, and no multiple of a shorter candidate (one chosen before its divisor).
  std::sort(chosen.begin(), chosen.end());
  chosen.erase(std::remove_if(chosen.begin(), chosen.end(),
                              [&](int k) {
                                return std::any_of(chosen.begin(), chosen.end(), [k](int c) {
                                  return c < k && k % c == 0;
                                });
                              }),
               chosen.end());
  if (chosen.empty()) chosen.push_back(1);
  return chosen;
}

OrbitRefinement refine_orbit(StroboscopicMap& map, const std::vector<Vector>& points,
                             const Vector& last_state, const RefinementOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (last_state.size() != map.state_size()) {
    throw InputError(fmt::format("last state has {} components, the state {}", last_state.size(),
                                 map.state_size()));
  }
  if (!last_state.allFinite()) throw InputError("last state is not finite");

  OrbitRefinement r;
  const std::vector<int> periods = candidate_periods(points, options.max_period, options.candidates);
  for (int k : periods) {
    r.tried.push_back(k);
    ShootingOptions shooting = options.shooting;
    shooting.period = k;
    shooting.multipliers = true;
    try {
      PeriodicOrbit orbit = find_periodic_orbit(map, last_state, shooting);
      // The least period: the shortest divisor j of k with φ_{jT}(y) = y to Newton's tolerance.
      const double scale = shooting.tolerance * std::max(1.0, inf_norm(orbit.state));
      for (int j = 1; j < k; ++j) {
        if (k % j != 0) continue;
        if (inf_norm(map.advance(orbit.state, j) - orbit.state) <= 10 * scale) {
          shooting.period = j;
          orbit = find_periodic_orbit(map, orbit.state, shooting);
          break;
        }
      }
      r.found = true;
      r.orbit = std::move(orbit);
      break;
    } catch (const ShootingError& e) {
      r.failure = e.what();
    } catch (const DivergenceError& e) {
      r.failure = e.what();
    }
  }
  if (!r.found) {
    if (r.failure.empty()) r.failure = "no candidate period";
    return r;
  }

  // The distance from the motion to the nearest of the orbit's k points at phase 0.
  const int k = r.orbit.period;
  r.tolerance = options.on_orbit_tolerance * std::max(1.0, inf_norm(r.orbit.state));
  Vector y = r.orbit.state;
  r.distance = inf_norm(last_state - y);
  for (int j = 1; j < k; ++j) {
    y = map.advance(y, 1);
    r.distance = std::min(r.distance, inf_norm(last_state - y));
  }
  r.on_orbit = r.distance <= r.tolerance;
  const FloquetMultipliers& mu = r.orbit.multipliers;
  r.attracting = mu.converged && mu.stable();
  const double rho = mu.largest_modulus();
  r.contraction_per_period = rho > 0 ? std::pow(rho, 1.0 / k) : 0.0;
  if (r.attracting && !r.on_orbit) {
    r.periods_to_settle = rho > 0 ? k * std::log(r.tolerance / r.distance) / std::log(rho) : k;
  }
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
  if (attracting) {
    return fmt::format("{}, attracting ({}): the motion approaches it, {:.1e} away, reached after "
                       "about {:.0f} more periods",
                       name, rate, distance, std::ceil(periods_to_settle));
  }
  if (!orbit.multipliers.converged) {
    return fmt::format("{}, stability undetermined (Arnoldi did not converge; {}), {:.1e} away",
                       name, rate, distance);
  }
  return fmt::format("{}, unstable ({}), {:.1e} away: it does not describe the motion", name,
                     rate, distance);
}

}  // namespace pwl::orbits
