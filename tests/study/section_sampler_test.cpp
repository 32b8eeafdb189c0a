// Poincaré sections sampled through an integrator (section_sampler.hpp) against independent
// truth: hyperplane crossings of the exact event-driven solver against the same flow's zero
// located by bisection, the PIM's crossings against the exact ones at its order, stroboscopic
// points at a phase against an independent integration to those times, and the pipeline's
// section points, description and journal records.
#include "pwl/study/section_sampler.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <cmath>
#include <string>
#include <vector>

#include "pwl/errors.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/study/sweep_journal.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// Figure 4a's chain from rest: its first periods pass through many contact switches.
PointCase figure_4a() { return PointCase(paper_five_dof_case("4a")); }

MethodSettings settings_of(const std::string& method, double period, int steps_per_period,
                           double tolerance = 1e-10, bool locate_kinks = false) {
  MethodSettings m;
  m.method = parse_method(method);
  m.tolerance = tolerance;
  m.locate_kinks = locate_kinks;
  return m.for_period(period, steps_per_period);
}

PoincareSection hyperplane(Index component, double level, CrossingDirection direction) {
  PoincareSection s;
  s.kind = PoincareSection::Kind::hyperplane;
  s.hyperplane.component = component;
  s.hyperplane.level = level;
  s.hyperplane.direction = direction;
  return s;
}

// Every crossing of `section` over [0, periods T] by `method` from rest.
std::vector<Crossing> crossings_by(const std::string& method, int steps_per_period,
                                   const PoincareSection& section, int periods) {
  const PointCase c = figure_4a();
  const MethodSettings m = settings_of(method, c.period, steps_per_period);
  auto integrator = make_integrator(c.structure, m);
  SectionSampler sampler(*integrator, c.structure, c.period, section, m, steps_per_period);
  std::vector<Crossing> found;
  sampler.record_crossings([&](const Crossing& crossing) { found.push_back(crossing); });
  sampler.advance_to(periods * c.period);
  return found;
}

// The exact times of the crossings near `estimates`: each bracketed by [t - width, t + width] on
// the exact flow (one solver carried along from rest to the left end, in time order) and
// bisected to the last bit on the exact flow from there (the event-driven solver lands exactly on
// any time). Independent of the section's interpolation.
std::vector<double> bisected_times(const std::vector<Crossing>& estimates,
                                   const PoincareSection& section, double width) {
  const PointCase c = figure_4a();
  const MethodSettings m = settings_of("exact", c.period, 200);
  auto carried = make_integrator(c.structure, m);
  auto probe = make_integrator(c.structure, m);
  const Index n = c.structure.dofs();
  const Index i = section.hyperplane.component;
  const double level = section.hyperplane.level;
  std::vector<double> times;
  for (const Crossing& estimate : estimates) {
    double lo = estimate.t - width;
    double hi = estimate.t + width;
    carried->advance_to(lo);
    const double start = lo;
    const Vector x_lo = carried->position(), v_lo = carried->velocity();
    const auto g = [&](double t) {
      probe->set_state(start, x_lo, v_lo);
      probe->advance_to(t);
      Vector s(2 * n);
      s << probe->position(), probe->velocity();
      return s[i] - level;
    };
    const double g_lo = (i < n ? x_lo[i] : v_lo[i - n]) - level;
    const double g_hi = g(hi);
    // The bracket holds the crossing, in its direction.
    REQUIRE(g_lo * g_hi < 0.0);
    REQUIRE((g_hi > 0.0) == estimate.upward);
    for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double g_mid = g(mid);
      if ((g_mid < 0.0) == (g_lo < 0.0)) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    times.push_back(0.5 * (lo + hi));
  }
  return times;
}

double largest_time_error(const std::vector<Crossing>& found, const std::vector<double>& truth) {
  REQUIRE(found.size() == truth.size());
  double worst = 0.0;
  for (std::size_t j = 0; j < found.size(); ++j) {
    worst = std::max(worst, std::abs(found[j].t - truth[j]));
  }
  return worst;
}

}  // namespace

TEST_CASE("The exact solver's hyperplane crossings match bisection on its exact flow",
          "[section]") {
  // v5 = 0 going down and x3 = 0.1 both ways, over 12 periods from rest (contacts switching).
  const PointCase c = figure_4a();
  const Index n = c.structure.dofs();
  for (const PoincareSection& section : {hyperplane(n + 4, 0.0, CrossingDirection::down),
                                         hyperplane(2, 0.1, CrossingDirection::both)}) {
    const std::vector<Crossing> coarse = crossings_by("exact", 200, section, 12);
    const std::vector<Crossing> fine = crossings_by("exact", 400, section, 12);
    REQUIRE(coarse.size() >= 8);
    REQUIRE(fine.size() == coarse.size());
    const std::vector<double> truth = bisected_times(coarse, section, 1e-3);
    const double error_200 = largest_time_error(coarse, truth);
    const double error_400 = largest_time_error(fine, truth);
    // The exact solver's states are exact at the samples (at most T/200 apart), so the crossing
    // times err by the cubic Hermite interpolation alone: about h^4 |g^(4)| / (384 |g'|), with
    // h = T/200 = 0.031, h^4 = 1e-6, |g^(4)| a few units on this chain (frequencies up to about
    // 2.2 rad per unit time, amplitudes about 2), |g'| rarely below 0.1: below 1e-6. Halving h
    // divides it by 8 to 16 (O(h^3) over a step where a spring switches, O(h^4) elsewhere) or
    // more. Measured: v5 = 0 down 6.6e-9 and 2.3e-10, x3 = 0.1 both ways 7.9e-8 and 1.2e-9.
    INFO("crossings " << coarse.size() << ", largest time error at T/200 " << error_200
                      << ", at T/400 " << error_400);
    CHECK(error_200 < 1e-6);
    CHECK(error_400 < error_200 / 6);
    for (std::size_t j = 0; j < coarse.size(); ++j) {
      CHECK(coarse[j].state[section.hyperplane.component] == section.hyperplane.level);
    }
  }
}

TEST_CASE("The PIM's crossings converge to the exact ones at its second order", "[section]") {
  const PointCase c = figure_4a();
  const Index n = c.structure.dofs();
  const PoincareSection section = hyperplane(n + 4, 0.0, CrossingDirection::down);
  const std::vector<Crossing> exact = crossings_by("exact", 400, section, 12);
  const std::vector<Crossing> pim_100 = crossings_by("pim", 100, section, 12);
  const std::vector<Crossing> pim_200 = crossings_by("pim", 200, section, 12);
  std::vector<double> truth;
  for (const Crossing& x : exact) truth.push_back(x.t);
  const double error_100 = largest_time_error(pim_100, truth);
  const double error_200 = largest_time_error(pim_200, truth);
  INFO("largest crossing-time error of the PIM at T/100 " << error_100 << ", at T/200 "
                                                          << error_200);
  // The PIM's state errs by O(η^2) (about 1e-3 at T/200 on this case), its crossing times by that
  // over |g'|; the interpolation's O(η^4) is far below. Halving η divides the error by 4
  // (measured: 1.24e-3 at T/100, 3.7e-4 at T/200).
  CHECK(error_200 < 5e-3);
  CHECK(error_100 / error_200 > 3.0);
  CHECK(error_100 / error_200 < 5.0);
}

TEST_CASE("Stroboscopic points at a phase equal an independent integration to those times",
          "[section]") {
  const PointCase c = figure_4a();
  const Index n = c.structure.dofs();
  const int periods = 8;
  // The truth: kink-located rkf78 at 1e-12, integrated to each time (k + phase) T itself.
  const auto truth_at = [&](double phase) {
    auto rkf = make_integrator(c.structure, settings_of("rkf78", c.period, 200, 1e-12, true));
    std::vector<Vector> states;
    for (int k = 0; k < periods; ++k) {
      rkf->advance_to((k + phase) * c.period);
      Vector s(2 * n);
      s << rkf->position(), rkf->velocity();
      states.push_back(s);
    }
    return states;
  };
  const auto sampled = [&](const std::string& method, double phase, bool* interpolated) {
    const MethodSettings m = settings_of(method, c.period, 200);
    auto integrator = make_integrator(c.structure, m);
    PoincareSection section;
    section.phase = phase;
    SectionSampler sampler(*integrator, c.structure, c.period, section, m, 200);
    std::vector<Vector> states;
    for (int k = 0; k < periods; ++k) {
      const StrobePoint p = sampler.advance_to_strobe(k);
      CHECK(std::abs(p.t - (k + phase) * c.period) < 1e-12 * c.period * (k + 1));
      *interpolated = p.interpolated;
      states.push_back(p.state);
    }
    return states;
  };
  const auto largest = [](const std::vector<Vector>& a, const std::vector<Vector>& b) {
    double worst = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      worst = std::max(worst, (a[k] - b[k]).cwiseAbs().maxCoeff());
    }
    return worst;
  };
  bool interpolated = true;
  // The exact solver lands on (k + 0.25) T itself.
  const double exact_error = largest(sampled("exact", 0.25, &interpolated), truth_at(0.25));
  CHECK_FALSE(interpolated);
  // The switching PIM (fifth order) at T/200: phase 0.25 is 50 steps, on its grid; 0.1225 is
  // 24.5 steps, interpolated between two grid points by cubic Hermite on (x, v) and (v, a).
  const double landed_error =
      largest(sampled("pim-switching", 0.25, &interpolated), truth_at(0.25));
  CHECK_FALSE(interpolated);
  const double between_error =
      largest(sampled("pim-switching", 0.1225, &interpolated), truth_at(0.1225));
  CHECK(interpolated);
  INFO("largest state difference: exact " << exact_error << ", switching PIM landed "
                                          << landed_error << ", interpolated " << between_error);
  // The exact solver against rkf78 at tolerance 1e-12 over 8 periods (measured 1.5e-12).
  CHECK(exact_error < 1e-10);
  // The switching PIM's own error at T/200 (measured 2.5e-10), then the interpolation's O(η^4)
  // on top of it: η^4/384 = 2.5e-9 times the fourth derivative of the state, a few units here
  // (measured 1.8e-8).
  CHECK(landed_error < 1e-8);
  CHECK(between_error < 1e-7);
}

TEST_CASE("At phase 0 the sampler makes the very calls of an integration to kT", "[section]") {
  const PointCase c = figure_4a();
  const MethodSettings m = settings_of("pim", c.period, 200);
  auto direct = make_integrator(c.structure, m);
  auto sampled = make_integrator(c.structure, m);
  SectionSampler sampler(*sampled, c.structure, c.period, PoincareSection{}, m, 200);
  for (int k = 1; k <= 20; ++k) {
    direct->advance_to(k * c.period);
    const StrobePoint p = sampler.advance_to_strobe(k);
    REQUIRE(p.t == direct->time());
    REQUIRE(p.state.head(5) == direct->position());
    REQUIRE(p.state.tail(5) == direct->velocity());
  }
}

TEST_CASE("The accelerations are the time derivative of the exact velocities", "[section]") {
  const PointCase c = figure_4a();
  const StateRate rate(c.structure);
  auto exact = make_integrator(c.structure, settings_of("exact", c.period, 200));
  const double h = 1e-4;
  for (double t : {1.0, 3.7, 8.2}) {
    exact->advance_to(t - h);
    const Vector before = exact->velocity();
    exact->advance_to(t);
    const Vector x = exact->position(), v = exact->velocity();
    exact->advance_to(t + h);
    const Vector after = exact->velocity();
    // Central difference: O(h^2) = 1e-8 times the third derivative of v.
    CHECK((rate.acceleration(t, x, v) - (after - before) / (2 * h)).cwiseAbs().maxCoeff() < 1e-6);
  }
}

TEST_CASE("Sections are parsed, named and checked", "[section]") {
  const PoincareSection v3 = parse_poincare_section(" v3 = 0 , down ", 5);
  CHECK(v3.hyperplane.component == 7);
  CHECK(v3.hyperplane.direction == CrossingDirection::down);
  CHECK(v3.text(5) == "v3=0,down");
  CHECK(v3.label(5) == "v3 = 0 going down");
  const PoincareSection x2 = parse_poincare_section("x2=0.1,up", 5);
  CHECK(x2.hyperplane.component == 1);
  CHECK(x2.hyperplane.level == 0.1);
  CHECK(x2.text(5) == "x2=0.1,up");
  CHECK(parse_poincare_section("strobe", 5).is_default());
  PoincareSection quarter;
  quarter.phase = 0.25;
  CHECK(quarter.label(5) == "t = (k + 0.25)T");
  CHECK_THROWS_WITH(parse_poincare_section("v6=0,down", 5), Catch::Contains("v6 names no state"));
  CHECK_THROWS_WITH(parse_poincare_section("v3=0", 5), Catch::Contains("give strobe, or"));
  CHECK_THROWS_WITH(parse_poincare_section("v3=zero,up", 5), Catch::Contains("'zero' is not a"));
  CHECK_THROWS_WITH(parse_poincare_section("v3=nan,up", 5), Catch::Contains("not finite"));
  CHECK_THROWS_WITH(parse_poincare_section("v3=0,sideways", 5), Catch::Contains("'sideways'"));
  CHECK_THROWS_WITH(parse_poincare_section("w3=0,up", 5), Catch::Contains("not a state component"));
  CHECK_THROWS_WITH(parse_poincare_section("x0=0,up", 5), Catch::Contains("not a state component"));
  std::string why;
  quarter.phase = 1.0;
  CHECK_FALSE(quarter.is_valid(5, &why));
  CHECK_THAT(why, Catch::Contains("0 <= phase < 1"));
}

TEST_CASE("The pipeline records a hyperplane's crossings and still classifies the strobe",
          "[section]") {
  const PointCase c = figure_4a();
  const Index n = c.structure.dofs();
  PointSettings s;
  s.transient_periods = 100;
  s.recorded_periods = 100;
  s.components = {4, 9};
  const PointResult strobe = evaluate_point(c, Vector::Zero(2 * n), s);
  s.section = hyperplane(n + 4, 0.0, CrossingDirection::down);
  const PointResult crossings = evaluate_point(c, Vector::Zero(2 * n), s);
  // The same motion, classified alike (figure 4a: period-2).
  CHECK(crossings.regime == strobe.regime);
  CHECK(crossings.regime == "period-2");
  CHECK(crossings.lambda1 == strobe.lambda1);
  CHECK(crossings.K == strobe.K);
  CHECK(crossings.final_state == strobe.final_state);
  CHECK(strobe.section_times.empty());
  // Period-2: the last mass turns back (v5 = 0 going down) once or more per 2 periods; every
  // recorded crossing lies in the recorded periods and has v5 = 0.
  REQUIRE(crossings.rows() >= 50);
  REQUIRE(crossings.section_times.size() == static_cast<std::size_t>(crossings.rows()));
  for (int k = 0; k < crossings.rows(); ++k) {
    const double t = crossings.section_times[static_cast<std::size_t>(k)];
    CHECK(t > 100 * c.period);
    CHECK(t <= 200 * c.period);
    CHECK(crossings.poincare[static_cast<std::size_t>(2 * k + 1)] == 0.0);
  }
  // They are the crossings a sampler records along the same integration, in that window.
  const MethodSettings m = s.method_for(c.period);
  auto integrator = make_integrator(c.structure, m);
  SectionSampler sampler(*integrator, c.structure, c.period, s.section, m, 200);
  std::vector<double> times;
  sampler.advance_to(100 * c.period);
  sampler.record_crossings([&](const Crossing& x) { times.push_back(x.t); });
  sampler.advance_to(200 * c.period);
  CHECK(times == crossings.section_times);
  // The journal keeps the times; a stroboscopic record reads as before.
  const auto decoded = decode_record(encode_record(3, crossings));
  REQUIRE(decoded);
  CHECK(decoded->second.section_times == crossings.section_times);
  CHECK(decoded->second.poincare == crossings.poincare);
  // No count of times after a stroboscopic record's final state: its last token is the state's.
  const std::string strobe_line = encode_record(3, strobe);
  REQUIRE(strobe.final_state.size() > 0);
  CHECK(strobe_line.substr(strobe_line.rfind(' ') + 1) ==
        fmt::format("{:.17g}\n", strobe.final_state[strobe.final_state.size() - 1]));
  const auto strobe_decoded = decode_record(encode_record(3, strobe));
  REQUIRE(strobe_decoded);
  CHECK(strobe_decoded->second.section_times.empty());
}

TEST_CASE("A section other than the default is part of the settings' description", "[section]") {
  PointSettings s;
  const std::string plain = s.describe();
  CHECK(plain.find("section") == std::string::npos);
  CHECK(plain.find("phase") == std::string::npos);
  s.section.phase = 0.25;
  CHECK_THAT(s.describe(), Catch::Contains("phase = 0.25\n"));
  s.section = hyperplane(7, 0.0, CrossingDirection::down);
  CHECK_THAT(s.describe(), Catch::Contains("section = hyperplane\nsection_component = 7\n"
                                           "section_level = 0\nsection_direction = down\n"));
  std::string why;
  CHECK_FALSE(s.is_valid(3, &why));  // v4 of a 3-mass structure does not exist
  CHECK_THAT(why, Catch::Contains("component = 7 is out of range"));
}

TEST_CASE("Stroboscopic points at a phase through the pipeline", "[section]") {
  // The exact solver lands on (k + 0.3) T; the pipeline's points are its states there, and its
  // final state is at the next whole period, where a continuation's next point starts.
  const PointCase c = figure_4a();
  const Index n = c.structure.dofs();
  PointSettings s;
  s.transient_periods = 3;
  s.recorded_periods = 12;
  s.lyapunov = false;
  s.method.method = Method::exact;
  s.section.phase = 0.3;
  struct Points : PointObserver {
    std::vector<double> t;
    std::vector<Vector> states;
    void poincare_point(int, double time, const Vector& state) override {
      t.push_back(time);
      states.push_back(state);
    }
  } points;
  const PointResult r = evaluate_point(c, Vector::Zero(2 * n), s, &points);
  REQUIRE(points.states.size() == 12);
  auto truth = make_integrator(c.structure, s.method_for(c.period));
  for (int k = 4; k <= 15; ++k) {
    truth->advance_to((k + 0.3) * c.period);
    CHECK(points.t[static_cast<std::size_t>(k - 4)] == truth->time());
    CHECK((points.states[static_cast<std::size_t>(k - 4)].head(n) - truth->position())
              .cwiseAbs()
              .maxCoeff() < 1e-12);
  }
  truth->advance_to(16 * c.period);
  REQUIRE(r.final_state.size() == 2 * n);
  CHECK((r.final_state.head(n) - truth->position()).cwiseAbs().maxCoeff() < 1e-12);
}
