// Grazing bifurcations located where the gap's extreme along the orbit changes slowly with the
// parameter: on a 20-mass chain the grazings are located as on orbits closed near rounding. An
// orbit closed only to the shooting tolerance would place each to about that tolerance over the
// extreme's slope. Three continuations of a 20-mass chain on the exact solver: about 23 s in the
// Release build and beyond the 300 s limit under the sanitizers, so it runs in Release only
// (tests/CMakeLists.txt); the same polishing runs under the sanitizers in every other continuation
// test that locates a bifurcation.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

TEST_CASE("grazings on a 20-mass chain are located as on orbits closed to 1e-13", "[orbits]") {
  // Figure 4a's chain with 20 masses and loads ±1 alternating, θ from 1.98 to 2.32: seven
  // grazings, most of them where the gap's largest value moves slowly with θ. The reference is
  // the same continuation with every orbit closed to 1e-13. With the bifurcations' trial points
  // closed only to the default tolerance 1e-10, the grazings differed from the reference's by up
  // to 1.9e-9 (chord corrector) and 6.6e-10 (Newton); closed further, by at most 2.5e-11.
  constexpr int masses = 20;
  constexpr double end = 2.32;
  NondimensionalChain chain = paper_five_dof_case("4a");
  chain.masses = masses;
  chain.theta = 1.98;
  chain.amplitude.assign(masses, 1.0);
  for (int i = 1; i < masses; i += 2) chain.amplitude[static_cast<std::size_t>(i)] = -1.0;
  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
  const Vector guess = map.advance(Vector::Zero(2 * masses), 20);
  // The grazings up to `end` (the last step may pass it), in the order of the parameter.
  const auto grazings = [&](double tolerance, Corrector corrector) {
    ContinuationOptions o;
    o.parameter = analysis::SweepParameter::theta;
    o.start = chain.theta;
    o.end = end;
    o.corrector = corrector;
    o.shooting.tolerance = tolerance;
    const ContinuationResult r = continue_periodic_orbit(analysis::PointModel(chain), guess, o);
    std::vector<Bifurcation> g;
    for (const Bifurcation& b : r.bifurcations) {
      if (b.type == BifurcationType::grazing && b.parameter <= end) g.push_back(b);
    }
    std::sort(g.begin(), g.end(),
              [](const Bifurcation& a, const Bifurcation& b) { return a.parameter < b.parameter; });
    return g;
  };
  const std::vector<Bifurcation> reference = grazings(1e-13, Corrector::chord);
  REQUIRE(reference.size() == 7);
  for (Corrector corrector : {Corrector::chord, Corrector::newton}) {
    const std::vector<Bifurcation> located = grazings(ShootingOptions{}.tolerance, corrector);
    INFO(corrector_name(corrector) << " corrector");
    REQUIRE(located.size() == reference.size());
    for (std::size_t i = 0; i < located.size(); ++i) {
      const Bifurcation& g = located[i];
      INFO("grazing of spring " << g.spring << " at θ = " << g.parameter << ", reference "
                                << reference[i].parameter);
      CHECK(g.located);
      CHECK(g.spring == reference[i].spring);
      CHECK(g.at_largest_gap == reference[i].at_largest_gap);
      measured("grazing on the 20-mass chain: located - reference",
               g.parameter - reference[i].parameter);
      CHECK(std::abs(g.parameter - reference[i].parameter) <= 1e-10);
      // The located orbit itself is closed past the shooting tolerance, by a fresh integration.
      NondimensionalChain at = chain;
      at.theta = g.parameter;
      StroboscopicMap fresh(analysis::PointCase(at), MethodSettings{Method::exact}, 1);
      const Vector F = fresh.advance(g.state, 1) - g.state;
      const double scale = std::max(1.0, g.state.lpNorm<Eigen::Infinity>());
      measured("grazing on the 20-mass chain: residual of the located orbit",
               F.lpNorm<Eigen::Infinity>() / scale);
      CHECK(F.lpNorm<Eigen::Infinity>() / scale <= 1e-12);
    }
  }
}
