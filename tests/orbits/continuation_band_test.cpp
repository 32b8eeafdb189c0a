// A stable window that one coarse step jumps over. On the paper's 5-DOF chain of figure 6 the
// period-1 orbit is unstable at θ = 1.95 (a complex pair outside the unit circle), stable between
// two Neimark–Sacker points near θ = 1.9666 (that pair comes in) and 1.9884 (another pair goes
// out), and unstable again beyond: both ends of a step from θ ≈ 1.95 to ≈ 2.0 have one complex pair
// outside, the same signature, and the step explains nothing. With a band round the circle
// (ContinuationOptions::band; 0.05 unless set) continuation halves a step over which a multiplier
// near the circle moved more than half the band, so the window's two points are found and located,
// here checked against a bisection on θ of the largest multiplier's modulus of orbits found by
// plain Newton at tolerance 1e-13; dense (Newton and chord correctors) and matrix-free alike, and
// with the default band.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <complex>
#include <tuple>
#include <vector>

#include "continuation_cases.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

constexpr double kFrom = 1.95, kTo = 2.02;

NondimensionalChain chain_at(double theta) { return pwl::test::paper_case_at("6", theta); }

// max |μ| − 1 over the multipliers of Newton's orbit at θ, from `guess`.
double largest_off_circle(double theta, const Vector& guess) {
  StroboscopicMap map(analysis::PointCase(chain_at(theta)), MethodSettings{Method::exact}, 1);
  ShootingOptions options;
  options.tolerance = 1e-13;
  const PeriodicOrbit orbit = find_periodic_orbit(map, guess, options);
  double largest = 0;
  for (const std::complex<double>& mu : orbit.multipliers.values) {
    largest = std::max(largest, std::abs(mu));
  }
  return largest - 1.0;
}

// The zero of largest_off_circle between a and b (of opposite signs), by bisection to 1e-12.
double bisect(double a, double b, const Vector& guess) {
  const double fa = largest_off_circle(a, guess);
  REQUIRE(fa * largest_off_circle(b, guess) < 0);
  while (b - a > 1e-12) {
    const double m = 0.5 * (a + b);
    ((largest_off_circle(m, guess) > 0) == (fa > 0) ? a : b) = m;
  }
  return 0.5 * (a + b);
}

// Matrix-free, the leading multipliers are asked to cover the band too (ArnoldiOptions::margin),
// so that it is not narrowed to what six of them cover.
ContinuationOptions coarse(double band, Corrector corrector, ShootingSolver solver) {
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = kFrom;
  o.end = kTo;
  o.initial_step = 0.3;  // arclength in (y, θ): the first step reaches past θ = 2
  o.max_step = 0.1;
  o.corrector = corrector;
  o.band = band;
  if (solver == ShootingSolver::krylov) o.shooting.arnoldi.margin = band;
  return o;
}

std::vector<const Bifurcation*> neimark_sacker(const ContinuationResult& r) {
  std::vector<const Bifurcation*> out;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.type == BifurcationType::neimark_sacker) out.push_back(&b);
  }
  return out;
}

}  // namespace

TEST_CASE("a band round the unit circle finds the stable window a coarse step jumps over",
          "[orbits]") {
  const NondimensionalChain chain = chain_at(kFrom);
  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
  const Vector guess = map.advance(Vector::Zero(10), 200);

  // Without a band the coarse steps see the same signature at both ends and nothing between.
  const ContinuationResult blind =
      pwl::test::follow(chain, guess, coarse(0.0, Corrector::newton, ShootingSolver::dense),
                        ShootingSolver::dense);
  REQUIRE(neimark_sacker(blind).empty());
  CHECK(blind.band_cuts == 0);
  CHECK(std::isinf(blind.narrowest_band));  // no step checked

  // The two points, independently.
  const double comes_in = bisect(1.96, 1.975, guess);
  const double goes_out = bisect(1.98, 1.995, guess);
  INFO("bisection: " << comes_in << ", " << goes_out);

  // A band of 0.1 by each corrector and solver, and the default band (0.05) by Newton.
  const double fallback = ContinuationOptions{}.band;
  REQUIRE(fallback > 0);
  for (const auto& [solver, corrector, band] :
       {std::tuple{ShootingSolver::dense, Corrector::newton, 0.1},
        std::tuple{ShootingSolver::dense, Corrector::chord, 0.1},
        std::tuple{ShootingSolver::krylov, Corrector::newton, 0.1},
        std::tuple{ShootingSolver::dense, Corrector::newton, fallback}}) {
    INFO((solver == ShootingSolver::dense ? "dense, " : "matrix-free, ")
         << corrector_name(corrector) << ", band " << band);
    const ContinuationResult r =
        pwl::test::follow(chain, guess, coarse(band, corrector, solver), solver);
    CHECK(r.narrowest_band == band);  // every multiplier of the band known: never narrowed
    CHECK(r.matrix_free == (solver == ShootingSolver::krylov));
    CHECK(r.band_cuts > 0);
    const std::vector<const Bifurcation*> ns = neimark_sacker(r);
    REQUIRE(ns.size() == 2);
    for (const Bifurcation* b : ns) {
      CHECK(b->located);
      CHECK(std::abs(std::abs(b->multiplier) - 1.0) <= 1e-6);
      CHECK(std::abs(b->multiplier.imag()) > 0.1);
    }
    measured("band: Neimark-Sacker in - bisection", ns[0]->parameter - comes_in);
    measured("band: Neimark-Sacker out - bisection", ns[1]->parameter - goes_out);
    CHECK(std::abs(ns[0]->parameter - comes_in) <= 1e-8);
    CHECK(std::abs(ns[1]->parameter - goes_out) <= 1e-8);
    // The pairs differ: the one that comes in is not the one that goes out.
    CHECK(std::abs(std::arg(ns[0]->multiplier) - std::arg(ns[1]->multiplier)) > 0.3);
    // Stable in the window, unstable at both ends.
    for (const BranchPoint& p : r.points) {
      if (p.parameter > comes_in + 1e-6 && p.parameter < goes_out - 1e-6) {
        CHECK(p.orbit.multipliers.unstable_count() == 0);
      } else if (p.parameter < comes_in - 1e-6 || p.parameter > goes_out + 1e-6) {
        CHECK(p.orbit.multipliers.unstable_count() == 2);
      }
    }
  }
}
