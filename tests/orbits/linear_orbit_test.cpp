// Periodic orbits of linear forced damped structures, where everything is known in closed form:
// the orbit is the steady-state harmonic response, X = (K − ω²M + iωC)⁻¹ F, x(t) = Im(X e^{iωt}),
// and the Floquet multipliers are exp(λ_i T), λ_i the eigenvalues of the state matrix. One mass
// without gap springs, and two masses with a gap spring whose gap the motion never reaches.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::harmonic_response;
using pwl::test::set_distance;
using pwl::test::state_matrix;

namespace {

using Complex = std::complex<double>;

std::vector<Complex> expected_multipliers(const GapStructure& s, double period) {
  Eigen::EigenSolver<Matrix> eig(state_matrix(s));
  std::vector<Complex> mu;
  for (Index i = 0; i < eig.eigenvalues().size(); ++i)
    mu.push_back(std::exp(eig.eigenvalues()(i) * period));
  return mu;
}

GapStructure one_mass() {
  GapStructure s = pwl::test::single_mass(1.3, 0.15, 2.0);
  s.loads.push_back({0, 0.7, 1.1, 0.0});
  return s;
}

// Two masses, non-proportional damping, loads with phases on both, and a gap spring 10 away.
GapStructure two_masses() {
  GapStructure s;
  Matrix M(2, 2), C(2, 2), K(2, 2);
  M << 1.0, 0.0, 0.0, 2.0;
  C << 0.12, -0.05, -0.05, 0.05;
  K << 3.0, -1.0, -1.0, 1.0;
  s.mass = to_sparse(M);
  s.damping = to_sparse(C);
  s.stiffness = to_sparse(K);
  s.springs.push_back({1, 0, 1.0, 5.0, 10.0});  // x2 − x1 never reaches 10
  s.loads.push_back({0, 0.8, 0.9, 0.3});
  s.loads.push_back({1, -0.5, 0.9, 1.2});
  return s;
}

void check_linear_orbit(const GapStructure& s, double omega, const MethodSettings& method,
                        int steps) {
  const double T = 2 * M_PI / omega;
  StroboscopicMap map(analysis::PointCase(s, T), method, steps);
  ShootingOptions options;
  options.tolerance = 1e-13;
  const PeriodicOrbit orbit =
      find_periodic_orbit(map, Vector::Constant(s.dofs() * 2, 0.3), options);
  const Vector expected = harmonic_response(s, omega);
  INFO("method " << method_label(map.settings()) << ", steps " << steps);
  INFO("orbit " << orbit.state.transpose() << "\nexpected " << expected.transpose());
  const double error = (orbit.state - expected).lpNorm<Eigen::Infinity>();
  pwl::test::measured(method_label(map.settings()) + " linear orbit error", error);
  CHECK(error <= 1e-12);
  CHECK(orbit.exact_tangent);
  REQUIRE(orbit.multipliers.complete);
  const double distance = set_distance(expected_multipliers(s, T), orbit.multipliers.values);
  pwl::test::measured(method_label(map.settings()) + " linear multipliers error", distance);
  INFO("multipliers off by " << distance);
  CHECK(distance <= 1e-12);
  CHECK(orbit.stable());
  // A linear map: Newton lands in one step.
  CHECK(orbit.iterations <= 2);
}

}  // namespace

TEST_CASE("the periodic orbit of a forced damped mass is its harmonic response", "[orbits]") {
  check_linear_orbit(one_mass(), 1.1, MethodSettings{Method::exact}, 1);
}

TEST_CASE("the periodic orbit of two masses whose spring never touches is their harmonic response",
          "[orbits]") {
  const GapStructure s = two_masses();
  check_linear_orbit(s, 0.9, MethodSettings{Method::exact}, 1);
  // The orbit stays 10 away from the kink: far from touching.
  const Vector y = harmonic_response(s, 0.9);
  CHECK(std::abs(y(1) - y(0)) < 5.0);
}

TEST_CASE("the PIM's linear orbits are exact too (its load integrals are exact)", "[orbits]") {
  // Without a contact the PIM's step is the exact exponential with exact harmonic load integrals:
  // its O(η²) error comes only from the spring force inside a step (gap_oscillator_orbit_test
  // measures it), so here it agrees to rounding at any step.
  check_linear_orbit(one_mass(), 1.1, MethodSettings{Method::pim}, 40);
  check_linear_orbit(two_masses(), 0.9, MethodSettings{Method::pim}, 400);
}
