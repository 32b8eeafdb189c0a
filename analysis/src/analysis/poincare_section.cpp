// Hyperplane crossings and stroboscopic samples of a sampled flow, by linear and cubic Hermite
// interpolation (Hairer, Nørsett & Wanner, Solving ODEs I, §II.6).
#include "pwl/analysis/poincare_section.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

bool fail(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

void check_finite(const Vector& v, const char* name) {
  for (Index i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) throw InputError(fmt::format("{}[{}] = {} is not finite", name, i, v[i]));
  }
}

void check_step(const HyperplaneSection& section, double t0, const Vector& s0, double t1,
                const Vector& s1) {
  std::string why;
  if (!section.is_valid(&why)) throw InputError(why);
  if (!std::isfinite(t0) || !std::isfinite(t1) || !(t1 > t0)) {
    throw InputError(fmt::format("t0 = {}, t1 = {}: need finite times with t1 > t0", t0, t1));
  }
  if (s1.size() != s0.size()) {
    throw InputError(fmt::format("s1: size {} differs from s0's {}", s1.size(), s0.size()));
  }
  if (section.component >= s0.size()) {
    throw InputError(fmt::format("HyperplaneSection.component = {} is out of range for states of "
                                 "size {}",
                                 section.component, s0.size()));
  }
  check_finite(s0, "s0");
  check_finite(s1, "s1");
}

bool wanted(CrossingDirection direction, bool upward) {
  return direction == CrossingDirection::both || (direction == CrossingDirection::up) == upward;
}

// The cubic Hermite interpolant on θ in [0, 1] of a value with end values y0, y1 and end slopes
// (with respect to θ, i.e. already multiplied by the step) m0, m1.
struct Hermite {
  double y0, m0, y1, m1;

  double value(double s) const {
    const double s2 = s * s;
    const double s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * y1 +
           (s3 - s2) * m1;
  }
  double slope(double s) const {  // d/dθ
    const double s2 = s * s;
    return (6 * s2 - 6 * s) * y0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * y1 +
           (3 * s2 - 2 * s) * m1;
  }
};

// Roots in (0, 1) of the derivative of the Hermite cubic, sorted: where it turns.
std::vector<double> turning_points(const Hermite& h) {
  // value = a θ^3 + b θ^2 + c θ + d
  const double a = 2 * h.y0 + h.m0 - 2 * h.y1 + h.m1;
  const double b = -3 * h.y0 - 2 * h.m0 + 3 * h.y1 - h.m1;
  const double c = h.m0;
  // slope = A θ^2 + B θ + C
  const double A = 3 * a;
  const double B = 2 * b;
  const double C = c;
  std::vector<double> roots;
  if (A == 0.0) {
    if (B != 0.0) roots.push_back(-C / B);
  } else {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0.0) {
      // Stable quadratic formula: no cancellation between -B and the square root.
      const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      roots.push_back(q / A);
      if (q != 0.0) roots.push_back(C / q);
    }
  }
  std::vector<double> inside;
  for (double r : roots) {
    if (r > 0.0 && r < 1.0) inside.push_back(r);
  }
  std::sort(inside.begin(), inside.end());
  return inside;
}

// The root of value(θ) = 0 on [lo, hi], where the interpolant is monotone and changes sign:
// Newton steps, falling back to bisection whenever a step leaves the bracket.
double solve_monotone(const Hermite& h, double lo, double hi) {
  double g_lo = h.value(lo);
  double g_hi = h.value(hi);
  if (g_hi == 0.0) return hi;
  double s = lo + (hi - lo) * g_lo / (g_lo - g_hi);  // start from the secant
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double g = h.value(s);
    if (g == 0.0) return s;
    if ((g < 0.0) == (g_lo < 0.0)) {
      lo = s;
      g_lo = g;
    } else {
      hi = s;
      g_hi = g;
    }
    const double d = h.slope(s);
    double next = d != 0.0 ? s - g / d : lo - 1.0;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - s) <= 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, s) ||
        hi - lo <= 4 * std::numeric_limits<double>::epsilon()) {
      return next;
    }
    s = next;
  }
  return s;
}

// Cubic Hermite interpolation of a whole vector at θ, with derivative vectors (per unit time)
// scaled by the step.
Vector hermite_vector(const Vector& y0, const Vector& dy0, const Vector& y1, const Vector& dy1,
                      double step, double s) {
  const double s2 = s * s;
  const double s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * y0 + ((s3 - 2 * s2 + s) * step) * dy0 + (-2 * s3 + 3 * s2) * y1 +
         ((s3 - s2) * step) * dy1;
}

// Time derivative of the same interpolant.
Vector hermite_vector_rate(const Vector& y0, const Vector& dy0, const Vector& y1,
                           const Vector& dy1, double step, double s) {
  const double s2 = s * s;
  return ((6 * s2 - 6 * s) / step) * y0 + (3 * s2 - 4 * s + 1) * dy0 +
         ((-6 * s2 + 6 * s) / step) * y1 + (3 * s2 - 2 * s) * dy1;
}

// The Hermite interpolation of interpolate_state, without its checks (a.t < t < b.t).
StateSample hermite_state(const StateSample& a, const StateSample& b, double t) {
  const double step = b.t - a.t;
  const double s = (t - a.t) / step;
  StateSample out;
  out.t = t;
  out.x = hermite_vector(a.x, a.v, b.x, b.v, step, s);
  if (a.a.size() != 0 && b.a.size() != 0) {
    out.v = hermite_vector(a.v, a.a, b.v, b.a, step, s);
    out.a = (1.0 - s) * a.a + s * b.a;
  } else {
    out.v = hermite_vector_rate(a.x, a.v, b.x, b.v, step, s);
  }
  return out;
}

}  // namespace

StateSample interpolate_state(const StateSample& a, const StateSample& b, double t) {
  if (a.v.size() != a.x.size() || b.x.size() != a.x.size() || b.v.size() != a.x.size() ||
      (a.a.size() != 0 && a.a.size() != a.x.size()) ||
      (b.a.size() != 0 && b.a.size() != a.x.size())) {
    throw InputError(fmt::format("interpolate_state: samples of different sizes (x {} and {}, v {} "
                                 "and {}, a {} and {})",
                                 a.x.size(), b.x.size(), a.v.size(), b.v.size(), a.a.size(),
                                 b.a.size()));
  }
  if (!(a.t <= t && t <= b.t) || !(a.t < b.t) || !std::isfinite(t)) {
    throw InputError(fmt::format("interpolate_state: t = {} is not within the samples' [{}, {}]",
                                 t, a.t, b.t));
  }
  if (t == a.t) return a;
  if (t == b.t) return b;
  return hermite_state(a, b, t);
}

bool HyperplaneSection::is_valid(std::string* why) const {
  if (component < 0) {
    return fail(why, fmt::format("HyperplaneSection.component = {} must be >= 0", component));
  }
  if (!std::isfinite(level)) {
    return fail(why, fmt::format("HyperplaneSection.level = {} must be finite", level));
  }
  return true;
}

std::optional<Crossing> find_crossing(const HyperplaneSection& section, double t0, const Vector& s0,
                                      double t1, const Vector& s1) {
  check_step(section, t0, s0, t1, s1);
  const double g0 = s0[section.component] - section.level;
  const double g1 = s1[section.component] - section.level;
  const bool up = g0 < 0.0 && g1 >= 0.0;
  const bool down = g0 > 0.0 && g1 <= 0.0;
  if (!(up || down) || !wanted(section.direction, up)) return std::nullopt;
  const double s = g0 / (g0 - g1);  // in (0, 1]
  Crossing crossing;
  crossing.t = s == 1.0 ? t1 : t0 + s * (t1 - t0);
  crossing.state = s0 + s * (s1 - s0);
  crossing.state[section.component] = section.level;
  crossing.upward = up;
  return crossing;
}

std::optional<Crossing> find_crossing(const HyperplaneSection& section, double t0, const Vector& s0,
                                      const Vector& ds0, double t1, const Vector& s1,
                                      const Vector& ds1) {
  check_step(section, t0, s0, t1, s1);
  if (ds0.size() != s0.size() || ds1.size() != s0.size()) {
    throw InputError(fmt::format("ds0, ds1: sizes {} and {} differ from the state size {}",
                                 ds0.size(), ds1.size(), s0.size()));
  }
  check_finite(ds0, "ds0");
  check_finite(ds1, "ds1");
  const double step = t1 - t0;
  const Index i = section.component;
  const Hermite g{s0[i] - section.level, step * ds0[i], s1[i] - section.level, step * ds1[i]};

  std::vector<double> knots{0.0};
  for (double r : turning_points(g)) knots.push_back(r);
  knots.push_back(1.0);
  for (std::size_t piece = 0; piece + 1 < knots.size(); ++piece) {
    const double lo = knots[piece];
    const double hi = knots[piece + 1];
    // Exact end values, not the polynomial's rounding of them.
    const double g_lo = lo == 0.0 ? g.y0 : g.value(lo);
    const double g_hi = hi == 1.0 ? g.y1 : g.value(hi);
    const bool up = g_lo < 0.0 && g_hi >= 0.0;
    const bool down = g_lo > 0.0 && g_hi <= 0.0;
    if (!(up || down)) continue;
    if (!wanted(section.direction, up)) continue;
    const double s = hi == 1.0 && g_hi == 0.0 ? 1.0 : solve_monotone(g, lo, hi);
    Crossing crossing;
    crossing.t = s == 1.0 ? t1 : t0 + s * step;
    crossing.state = hermite_vector(s0, ds0, s1, ds1, step, s);
    crossing.state[i] = section.level;
    crossing.upward = up;
    return crossing;
  }
  return std::nullopt;
}

std::vector<Crossing> find_crossings(const HyperplaneSection& section,
                                     const std::vector<double>& times,
                                     const std::vector<Vector>& states,
                                     const std::vector<Vector>& derivatives) {
  if (states.size() != times.size()) {
    throw InputError(fmt::format("states: {} given for {} times", states.size(), times.size()));
  }
  if (!derivatives.empty() && derivatives.size() != times.size()) {
    throw InputError(fmt::format("derivatives: {} given for {} times (give none or one per time)",
                                 derivatives.size(), times.size()));
  }
  std::vector<Crossing> crossings;
  for (std::size_t n = 1; n < times.size(); ++n) {
    if (!(times[n] > times[n - 1])) {
      throw InputError(fmt::format("times[{}] = {} does not exceed times[{}] = {}", n, times[n],
                                   n - 1, times[n - 1]));
    }
    std::optional<Crossing> crossing =
        derivatives.empty()
            ? find_crossing(section, times[n - 1], states[n - 1], times[n], states[n])
            : find_crossing(section, times[n - 1], states[n - 1], derivatives[n - 1], times[n],
                            states[n], derivatives[n]);
    if (crossing) crossings.push_back(std::move(*crossing));
  }
  return crossings;
}

bool PoincareSection::is_valid(Index dofs, std::string* why) const {
  if (!(phase >= 0.0 && phase < 1.0)) {
    return fail(why, fmt::format("PoincareSection.phase = {} must be a fraction of the forcing "
                                 "period, 0 <= phase < 1",
                                 phase));
  }
  if (stroboscopic()) return true;
  if (!hyperplane.is_valid(why)) return false;
  if (hyperplane.component >= 2 * dofs) {
    return fail(why, fmt::format("HyperplaneSection.component = {} is out of range for a state of "
                                 "{} components",
                                 hyperplane.component, 2 * dofs));
  }
  return true;
}

namespace {

std::string component_text(Index component, Index dofs) {
  return component < dofs ? fmt::format("x{}", component + 1)
                          : fmt::format("v{}", component - dofs + 1);
}

const char* direction_text(CrossingDirection direction) {
  switch (direction) {
    case CrossingDirection::up: return "up";
    case CrossingDirection::down: return "down";
    case CrossingDirection::both: return "both";
  }
  return "both";
}

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

}  // namespace

std::string PoincareSection::text(Index dofs) const {
  if (stroboscopic()) return "strobe";
  return fmt::format("{}={},{}", component_text(hyperplane.component, dofs), hyperplane.level,
                     direction_text(hyperplane.direction));
}

std::string PoincareSection::label(Index dofs) const {
  if (stroboscopic()) return phase == 0.0 ? "t = kT" : fmt::format("t = (k + {})T", phase);
  const char* going = hyperplane.direction == CrossingDirection::up     ? " going up"
                      : hyperplane.direction == CrossingDirection::down ? " going down"
                                                                         : "";
  return fmt::format("{} = {}{}", component_text(hyperplane.component, dofs), hyperplane.level,
                     going);
}

PoincareSection parse_poincare_section(std::string_view text, Index dofs) {
  const std::string_view whole = trimmed(text);
  PoincareSection section;
  if (whole == "strobe") return section;
  const std::string form = fmt::format(
      "give strobe, or a hyperplane as <x|v><mass>=<level>,<up|down|both> (e.g. v3=0,down) with "
      "mass 1..{}",
      dofs);
  const std::size_t equals = whole.find('=');
  const std::size_t comma = whole.find(',');
  if (equals == std::string_view::npos || comma == std::string_view::npos || comma < equals ||
      whole.find(',', comma + 1) != std::string_view::npos) {
    throw InputError(form);
  }
  const std::string_view name = trimmed(whole.substr(0, equals));
  const std::string level(trimmed(whole.substr(equals + 1, comma - equals - 1)));
  const std::string_view direction = trimmed(whole.substr(comma + 1));
  // The component: x or v and a whole number.
  long mass = 0;
  bool named = name.size() >= 2 && (name[0] == 'x' || name[0] == 'v');
  for (std::size_t i = 1; named && i < name.size(); ++i) {
    named = name[i] >= '0' && name[i] <= '9' && (i > 1 || name[i] != '0') && mass < 1000000000L;
    if (named) mass = 10 * mass + (name[i] - '0');
  }
  if (!named) throw InputError(fmt::format("'{}' is not a state component; {}", name, form));
  if (mass < 1 || mass > dofs) {
    throw InputError(fmt::format("{} names no state component of this structure: it has {} "
                                 "mass{} (x1..x{}, v1..v{})",
                                 name, dofs, dofs == 1 ? "" : "es", dofs, dofs));
  }
  char* end = nullptr;
  const double value = std::strtod(level.c_str(), &end);
  if (level.empty() || end != level.c_str() + level.size()) {
    throw InputError(fmt::format("the level '{}' is not a number; {}", level, form));
  }
  if (!std::isfinite(value)) {
    throw InputError(fmt::format("the level {} is not finite", level));
  }
  section.kind = PoincareSection::Kind::hyperplane;
  section.hyperplane.component = (name[0] == 'x' ? 0 : dofs) + (mass - 1);
  section.hyperplane.level = value;
  if (direction == "up") {
    section.hyperplane.direction = CrossingDirection::up;
  } else if (direction == "down") {
    section.hyperplane.direction = CrossingDirection::down;
  } else if (direction == "both") {
    section.hyperplane.direction = CrossingDirection::both;
  } else {
    throw InputError(fmt::format("the direction '{}' is not up, down or both", direction));
  }
  return section;
}

bool StroboscopicOptions::is_valid(std::string* why) const {
  if (!(snap_tolerance >= 0.0) || !(snap_tolerance < 0.5)) {
    return fail(why, fmt::format("StroboscopicOptions.snap_tolerance = {} must be in [0, 0.5)",
                                 snap_tolerance));
  }
  return true;
}

StroboscopicSampler::StroboscopicSampler(double t0, double period,
                                         const StroboscopicOptions& options)
    : t0_(t0), period_(period), options_(options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (!std::isfinite(t0)) throw InputError(fmt::format("t0 = {} must be finite", t0));
  if (!(period > 0.0) || !std::isfinite(period)) {
    throw InputError(fmt::format("period = {} must be finite and > 0", period));
  }
}

void StroboscopicSampler::observe(double t, const Vector& x, const Vector& v, const Vector& a) {
  if (!std::isfinite(t)) throw InputError(fmt::format("t = {} is not finite", t));
  if (v.size() != x.size()) {
    throw InputError(fmt::format("v: size {} differs from x's {}", v.size(), x.size()));
  }
  if (a.size() != 0 && a.size() != x.size()) {
    throw InputError(fmt::format("a: size {} differs from x's {} (give none or one per dof)",
                                 a.size(), x.size()));
  }
  check_finite(x, "x");
  check_finite(v, "v");
  check_finite(a, "a");
  StateSample current{t, x, v, a};
  if (!has_previous_) {
    has_previous_ = true;
    // The first target at or after t; one just before it is picked up once the step is known.
    next_k_ = std::max(0L, static_cast<long>(std::ceil((t - t0_) / period_)));
    previous_ = std::move(current);
    return;
  }
  const StateSample& p = previous_;
  if (x.size() != p.x.size()) {
    throw InputError(fmt::format("x: size {} at t = {} differs from the earlier samples' {}",
                                 x.size(), t, p.x.size()));
  }
  if (!(t > p.t)) {
    throw InputError(fmt::format("t = {} does not exceed the previous sample's t = {}", t, p.t));
  }
  const double step = t - p.t;
  const double snap = options_.snap_tolerance * step;
  auto target = [&](long k) { return t0_ + static_cast<double>(k) * period_; };
  if (!stepped_) {
    stepped_ = true;
    if (next_k_ > 0 && target(next_k_ - 1) >= p.t - snap) --next_k_;
  }

  for (; target(next_k_) <= t + snap; ++next_k_) {
    const double tk = target(next_k_);
    StateSample out;
    if (std::abs(tk - p.t) <= snap) {
      out = p;
    } else if (std::abs(tk - t) <= snap) {
      out = current;
    } else {
      out = hermite_state(p, current, tk);
    }
    out.t = tk;
    samples_.push_back(std::move(out));
  }
  previous_ = std::move(current);
}

std::vector<StateSample> stroboscopic_samples(const std::vector<StateSample>& samples, double t0,
                                              double period, const StroboscopicOptions& options) {
  StroboscopicSampler sampler(t0, period, options);
  for (const StateSample& s : samples) sampler.observe(s.t, s.x, s.v, s.a);
  return sampler.samples();
}

}  // namespace pwl::analysis
