// Secular growth through the point pipeline (evaluate_point, the classifier's rule 4a): a motion
// that grows without bound while staying far below the divergence bound is "unbounded", and the
// motions the paper and the studies classify keep their regimes.
//
// The growing case is the undamped linear resonance of issue 15 (`pwl analyze --n 1 --alpha 0
// --zeta 0 --theta 1 --loads 1`): one unit mass on a unit spring, no damping, its gap spring of
// stiffness 0, forced by sin(t) from rest, whose motion is x = (sin t - t cos t) / 2: at the
// strobe times t = 2πk the state is (x, v) = (-πk, 0), an amplitude exactly ∝ t. Detuned to θ =
// 0.97 the same oscillator beats, x = (sin θt - θ sin t) / (1 - θ²), bounded by 1 / (1 - θ).
#include <catch2/catch.hpp>
#include <cmath>
#include <optional>

#include "pwl/model/chain_builders.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// One undamped mass without contact stiffness, forced by sin(θ t): the command line.
NondimensionalChain oscillator(double theta, double zeta = 0.0) {
  NondimensionalChain c;
  c.masses = 1;
  c.alpha = {0.0};
  c.zeta = zeta;
  c.theta = theta;
  c.amplitude = {1.0};
  return c;
}

// Keeps the classification and the recorded points.
struct Evidence : PointObserver {
  std::optional<Classification> classification;
  std::vector<double> times;
  std::vector<Vector> points;
  void poincare_point(int, double t, const Vector& state) override {
    times.push_back(t);
    points.push_back(state);
  }
  void classified(const Classification& c, const PointResult&) override { classification = c; }
};

// `pwl analyze`'s default record: 500 transient periods, 500 recorded.
PointResult evaluate(const NondimensionalChain& chain, Evidence& evidence,
                     const PointSettings& settings = {}) {
  const PointCase point(chain);
  return evaluate_point(point, Vector::Zero(2 * chain.masses), settings, &evidence);
}

}  // namespace

TEST_CASE("the undamped resonance grows like t and is unbounded", "[sweep_point][growth]") {
  Evidence e;
  const PointResult r = evaluate(oscillator(1.0), e);
  // The record is the closed form x(2πk) = -πk, v(2πk) = 0 (the PIM integrates a linear motion
  // under a harmonic load exactly, up to rounding).
  REQUIRE(e.points.size() == 500);
  double worst = 0.0;
  for (std::size_t i = 0; i < e.points.size(); ++i) {
    const double k = e.times[i] / (2.0 * M_PI);
    worst = std::max({worst, std::abs(e.points[i][0] + M_PI * k) / (M_PI * k),
                      std::abs(e.points[i][1]) / (M_PI * k)});
  }
  INFO("largest relative difference from the closed form " << worst);
  CHECK(worst < 1e-8);
  CHECK(r.regime == "unbounded");
  CHECK(r.period == 0);
  CHECK(r.final_state.size() == 0);  // a continuation does not start from a growing state
  REQUIRE(e.classification.has_value());
  REQUIRE(e.classification->growth_exponent.has_value());
  INFO(e.classification->reason);
  CHECK(*e.classification->growth_exponent == Approx(1.0).margin(0.01));
  CHECK_THAT(e.classification->reason,
             Catch::StartsWith("unbounded: the amplitude grows like t^1.00 over the record"));
  // λ1 is zero (the tangent map of a period is a rotation): the indicators alone would have said
  // quasi-periodic.
  CHECK(std::abs(r.lambda1) < 1e-3);
}

TEST_CASE("the detuned undamped oscillator beats, bounded: not unbounded",
          "[sweep_point][growth]") {
  Evidence e;
  const PointResult r = evaluate(oscillator(0.97), e);
  // Bounded by 1 / (1 - θ) = 33.3 in x, and by θ / (1 - θ²) (1 + 1) in v.
  for (const Vector& p : e.points) CHECK(std::abs(p[0]) <= 1.0 / (1.0 - 0.97) + 1e-6);
  REQUIRE(e.classification.has_value());
  INFO(e.classification->reason);
  CHECK(r.regime == "quasi-periodic");
  REQUIRE(e.classification->growth_exponent.has_value());
  CHECK(std::abs(*e.classification->growth_exponent) < 0.2);
}

TEST_CASE("a damped resonance settles on its period-1 response", "[sweep_point][growth]") {
  Evidence e;
  const PointResult r = evaluate(oscillator(1.0, 0.05), e);
  CHECK(r.regime == "period-1");
  // Its amplitude is Q / (ζ θ) = 20 at resonance.
  CHECK(e.points.back().norm() == Approx(20.0).epsilon(1e-6));
}

TEST_CASE("a transient still settling is not growth", "[sweep_point][growth]") {
  // ζ = 0.002 from rest and nothing discarded: the amplitude builds up as 250 (1 - e^(-t/τ)),
  // τ = 2/ζ = 1000 (159 periods), over the 500 recorded periods: it rises in every block, but
  // ever more slowly. λ1 is left out, so that rule 4a alone has to tell: the exponent of its
  // second half is what does.
  PointSettings s;
  s.transient_periods = 0;
  s.recorded_periods = 500;
  s.lyapunov = false;
  Evidence settling;
  const PointResult r = evaluate(oscillator(1.0, 0.002), settling, s);
  REQUIRE(settling.classification.has_value());
  INFO(settling.classification->reason);
  CHECK(r.regime != "unbounded");
  REQUIRE(settling.classification->growth_exponent.has_value());
  CHECK(*settling.classification->growth_exponent < 0.75);
  // With λ1, as the studies run it: negative (-πζ per period), so that rule 4a does not run.
  Evidence with_lyapunov;
  s.lyapunov = true;
  const PointResult l = evaluate(oscillator(1.0, 0.002), with_lyapunov, s);
  CHECK(l.regime != "unbounded");
  CHECK(l.lambda1 == Approx(-M_PI * 0.002).epsilon(0.05));
  REQUIRE(with_lyapunov.classification.has_value());
  CHECK_FALSE(with_lyapunov.classification->growth_exponent.has_value());
}

TEST_CASE("the paper's regimes are kept: period-2, period-7 and chaos", "[sweep_point][growth]") {
  // Figure 4a and 4b as pwl analyze runs them, figure 6 as cli_analyze_chaotic does.
  for (const auto& [figure, regime] : {std::pair<std::string, std::string>{"4a", "period-2"},
                                       {"4b", "period-7"},
                                       {"6", "chaotic"}}) {
    Evidence e;
    const PointResult r = evaluate(paper_five_dof_case(figure), e);
    INFO("figure " << figure << ": " << e.classification->reason);
    CHECK(r.regime == regime);
  }
}
