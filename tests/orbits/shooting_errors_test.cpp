// How shooting fails, and how it avoids failing: Newton that runs out of iterations says so with
// the residual it reached (ShootingError), options or inputs that cannot work are refused up
// front (InputError naming the field and its value), and a guess far from the orbit is reached by
// damped steps.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <string>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;

namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The message of the InputError that `f` throws ("" when it throws none).
template <typename F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Newton out of iterations throws a ShootingError with the residual of its orbit guess",
          "[orbits]") {
  StroboscopicMap map(analysis::PointCase(paper_five_dof_case("4a")), MethodSettings{Method::exact},
                      1);
  const Vector far = Vector::Constant(10, 5.0);
  const double start = (map.advance(far, 1) - far).lpNorm<Eigen::Infinity>();
  ShootingOptions options;
  options.max_iterations = 1;
  try {
    find_periodic_orbit(map, far, options);
    FAIL("no ShootingError");
  } catch (const ShootingError& e) {
    const std::string message = e.what();
    INFO(message);
    CHECK(contains(message, "residual"));
    CHECK(contains(message, "did not converge"));
    CHECK(contains(message, fmt::format("{:.3e}", e.residual())));
    CHECK(e.iterations() == 1);
    // One Newton step was taken: the residual went down but is far from the tolerance.
    CHECK(std::isfinite(e.residual()));
    CHECK(e.residual() < start);
    CHECK(e.residual() > 1e-6);
  }
  // A ShootingError is a pwl::Error (callers that catch every pwl failure catch it).
  CHECK_THROWS_AS(find_periodic_orbit(map, far, options), Error);
}

TEST_CASE("shooting options and inputs that cannot work are refused naming the field (orbits)",
          "[orbits]") {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  StroboscopicMap exact(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
  StroboscopicMap pim(analysis::PointCase(chain), MethodSettings{Method::pim}, 200);
  const Vector y = Vector::Zero(10);
  const auto refused = [&](StroboscopicMap& map, const ShootingOptions& o, const Vector& guess) {
    return input_error([&] { find_periodic_orbit(map, guess, o); });
  };

  ShootingOptions o;
  o.period = 0;
  CHECK(contains(refused(exact, o, y), "period = 0"));
  o = {};
  o.shots = 0;
  CHECK(contains(refused(exact, o, y), "shots = 0"));
  o = {};
  o.shots = 3;  // 200 steps do not cut into 3 equal arcs on the PIM's grid ...
  const std::string grid = refused(pim, o, y);
  CHECK(contains(grid, "shots = 3"));
  CHECK(contains(grid, "200 steps"));
  CHECK(refused(exact, o, y).empty());  // ... the exact solver's arcs may end anywhere
  o.period = 3;                         // 600 steps do
  CHECK(refused(pim, o, y).empty());
  o = {};
  o.tolerance = 0;
  CHECK(contains(refused(exact, o, y), "tolerance = 0"));
  o = {};
  o.max_iterations = 0;
  CHECK(contains(refused(exact, o, y), "max iterations = 0"));
  o = {};
  o.max_forcing = 1.0;
  CHECK(contains(refused(exact, o, y), "max forcing = 1"));
  o.max_forcing = std::nan("");
  CHECK(contains(refused(exact, o, y), "max forcing = nan"));
  o = {};
  o.solver = ShootingSolver::krylov;
  o.shots = 2;
  CHECK(contains(refused(exact, o, y), "shots = 2"));
  o = {};
  o.arnoldi.count = 0;
  CHECK(contains(refused(exact, o, y), "floquet count = 0"));
  o = {};
  CHECK(contains(refused(exact, o, Vector::Zero(7)), "guess has 7 components"));
  CHECK(contains(refused(exact, o, Vector::Constant(10, std::nan(""))), "guess is not finite"));

  CHECK(contains(input_error([] { parse_shooting_solver("newton"); }), "\"newton\""));
  CHECK(parse_shooting_solver("krylov") == ShootingSolver::krylov);
  CHECK(contains(input_error([&] {
                   StroboscopicMap bad(analysis::PointCase(make_chain(chain), 0.0),
                                       MethodSettings{Method::exact}, 1);
                 }),
                 "forcing period = 0"));
  CHECK(contains(input_error([] { floquet_multipliers(Matrix::Zero(2, 3)); }), "2 x 3"));
}

TEST_CASE("dense Newton shortens the steps that would raise the residual and still converges",
          "[orbits]") {
  // Far from figure 4a's period-1 orbit the map's contacts differ from the orbit's, a full
  // Newton step on the local linearisation can overshoot, and the step is halved until |G|_2
  // falls (each halving one more integration of the map). Every guess must still reach the orbit
  // Newton finds from the transient's state (measured: the guesses below the orbit take one
  // halved step, 11 integrations for 8 iterations; those above take none).
  StroboscopicMap map(analysis::PointCase(paper_five_dof_case("4a")), MethodSettings{Method::exact},
                      1);
  const PeriodicOrbit near = find_periodic_orbit(map, map.advance(Vector::Zero(10), 200));
  int damped = 0;
  for (double scale : {3.0, 10.0, 30.0}) {
    for (double sign : {1.0, -1.0}) {
      const Vector guess = sign * scale * Vector::LinSpaced(10, 1.0, 2.0);
      const PeriodicOrbit far = find_periodic_orbit(map, guess);
      INFO("guess " << sign * scale << ": " << far.iterations << " iterations, "
                    << far.evaluations << " integrations");
      CHECK((far.state - near.state).lpNorm<Eigen::Infinity>() <= 1e-9);
      // One integration a full step (with its tangent) and one for the guess: more means halvings.
      if (far.evaluations > far.iterations + 1) ++damped;
    }
  }
  CHECK(damped > 0);
}
