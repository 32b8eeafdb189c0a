// The chord corrector of continuation against Newton's. Both solve the same bordered system to the
// same tolerance, so they must find the same bifurcations (type, spring) at the same parameters
// to the location tolerance, and every point the chord corrector accepts must be an orbit when
// checked by a fresh integration of the map. And the chord corrector is there to form fewer
// monodromies: about one an accepted point (and one a trial point of a bifurcation other than
// grazing), where Newton forms one at every iterate. (The two take different
// steps, so the branches' points differ; their bifurcations do not.)
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

struct Scene {
  std::string name;
  NondimensionalChain chain;  // at the start of the range
  double end = 0.0;
  Vector guess;
  bool switch_branches = false;  // onto one period-2 branch, 80 points a branch
  double step = 0.0;             // initial and largest step (0: the defaults)
};

// The hysteresis of the hardening gap oscillator (two folds, grazings), θ 0.8 -> 2; figure 4a's
// chain from θ = 1.1 to 1.2, from its period-1 orbit: a period doubling, and the period-2 branch
// born there.
std::vector<Scene> scenes() {
  std::vector<Scene> s;
  s.push_back({"gap oscillator", pwl::test::hardening_oscillator(0.8), 2.0, Vector::Zero(2)});
  NondimensionalChain fig4a = paper_five_dof_case("4a");
  fig4a.theta = 1.1;
  StroboscopicMap map(analysis::PointCase(fig4a), MethodSettings{Method::exact}, 1);
  const auto points = pwl::test::poincare_points(map, Vector::Zero(10), 300, 2);
  const Vector orbit = find_periodic_orbit(map, 0.5 * (points[0] + points[1])).state;
  s.push_back({"figure 4a", fig4a, 1.2, orbit, true});
  // A first and largest step of 0.5 in θ: the monodromy of the last point can be far from the
  // next one's, and the chord steps stall.
  s.push_back({"gap oscillator, long steps", pwl::test::hardening_oscillator(0.8), 2.0,
               Vector::Zero(2), false, 0.5});
  return s;
}

ContinuationResult run(const Scene& scene, Corrector corrector) {
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = scene.chain.theta;
  o.end = scene.end;
  o.corrector = corrector;
  o.initial_step = scene.step;
  o.max_step = scene.step;
  if (scene.switch_branches) {
    o.switch_branches = true;
    o.max_branches = 1;
    o.max_points = 80;
  }
  return continue_periodic_orbit(analysis::PointModel(scene.chain), scene.guess, o);
}

}  // namespace

TEST_CASE("the chord corrector finds Newton's bifurcations with fewer monodromies", "[orbits]") {
  for (const Scene& scene : scenes()) {
    INFO(scene.name);
    const ContinuationResult chord = run(scene, Corrector::chord);
    const ContinuationResult newton = run(scene, Corrector::newton);
    REQUIRE(!chord.bifurcations.empty());
    REQUIRE(chord.bifurcations.size() == newton.bifurcations.size());
    for (std::size_t i = 0; i < chord.bifurcations.size(); ++i) {
      const Bifurcation& a = chord.bifurcations[i];
      const Bifurcation& b = newton.bifurcations[i];
      INFO(bifurcation_name(a.type) << " at " << a.parameter << ", spring " << a.spring);
      CHECK(a.type == b.type);
      CHECK(a.spring == b.spring);
      CHECK(a.located);
      CHECK(b.located);
      const double difference = std::abs(a.parameter - b.parameter);
      measured("chord against Newton, bifurcation parameter", difference);
      CHECK(difference <= 1e-8);
    }
    const auto branches = [](const ContinuationResult& r) {
      return r.points.empty() ? -1 : r.points.back().branch;
    };
    CHECK(branches(chord) == (scene.switch_branches ? 1 : 0));
    CHECK(branches(newton) == branches(chord));
    // Every accepted point is a fixed point of the map, by a fresh integration.
    for (const BranchPoint& p : chord.points) {
      NondimensionalChain c = scene.chain;
      c.theta = p.parameter;
      StroboscopicMap map(analysis::PointCase(c), MethodSettings{Method::exact}, 1);
      const Vector F = map.advance(p.orbit.state, p.orbit.period) - p.orbit.state;
      const double scale = std::max(1.0, p.orbit.state.lpNorm<Eigen::Infinity>());
      CHECK(F.lpNorm<Eigen::Infinity>() / scale <= 1e-10);
    }
    // Monodromies over the whole range, the bifurcations' trial points included: Newton forms one
    // at each iterate, the chord corrector about one a point (and it takes larger steps).
    INFO("chord: " << chord.monodromies << " monodromies, " << chord.chord_stalls << " stalls, "
                   << chord.integrations << " integrations, " << chord.points.size()
                   << " points; newton: " << newton.monodromies << ", " << newton.integrations
                   << ", " << newton.points.size());
    CHECK(chord.monodromies < 0.5 * static_cast<double>(newton.monodromies));
    // The chord corrector's step follows the predictor's error and grows where Newton's would not.
    if (scene.step == 0) CHECK(chord.points.size() < newton.points.size());
    // Where the chord steps stall, the monodromy is formed again.
    if (scene.step > 0) CHECK(chord.chord_stalls > 0);
  }
}

TEST_CASE("the corrector's names round-trip and an unknown one is refused", "[orbits]") {
  for (Corrector c : {Corrector::automatic, Corrector::chord, Corrector::newton}) {
    CHECK(parse_corrector(corrector_name(c)) == c);
  }
  CHECK_THROWS_WITH(parse_corrector("secant"), Catch::Contains("secant"));
}

TEST_CASE("the automatic corrector is Newton up to 20 state components and chord above",
          "[orbits]") {
  for (int masses : {10, 11}) {
    NondimensionalChain c = paper_five_dof_case("4a");
    c.masses = masses;
    c.theta = 1.5;
    c.amplitude.assign(static_cast<std::size_t>(masses), 1.0);  // Q = ±1 alternating
    for (int i = 1; i < masses; i += 2) c.amplitude[static_cast<std::size_t>(i)] = -1.0;
    StroboscopicMap map(analysis::PointCase(c), MethodSettings{Method::exact}, 1);
    const Vector guess = map.advance(Vector::Zero(2 * masses), 50);
    ContinuationOptions o;
    o.parameter = analysis::SweepParameter::theta;
    o.start = 1.5;
    o.end = 1.6;
    o.max_points = 3;
    const ContinuationResult r = continue_periodic_orbit(analysis::PointModel(c), guess, o);
    INFO(masses << " masses");
    REQUIRE(r.points.size() == 3);
    CHECK(r.corrector == (masses == 10 ? Corrector::newton : Corrector::chord));
  }
}
