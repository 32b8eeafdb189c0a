// The precise-integration stepper against closed-form solutions: exact (to rounding) whenever no
// spring changes state inside a step, second order in η when one does.
#include <catch2/catch.hpp>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_integrator.hpp"
#include "pwl/integrators/reference_integrator.hpp"
#include "test_structures.hpp"

using namespace pwl;
using pwl::test::single_mass;

namespace {

PimOptions pim(double step, const std::string& solver = "block-pivoting") {
  PimOptions o;
  o.step = step;
  o.lcp_solver = parse_lcp_algorithm(solver);
  return o;
}

// x'' + 2ζω x' + ω² x = a sin Ωt from x(0) = x0, x'(0) = v0 (underdamped): the sum of the steady
// response and the free response that matches the initial state.
struct ForcedOscillator {
  double omega, zeta, a, big_omega, x0, v0;
  double position(double t) const {
    const double denom = std::pow(omega * omega - big_omega * big_omega, 2) +
                         std::pow(2 * zeta * omega * big_omega, 2);
    const double A = a * (omega * omega - big_omega * big_omega) / denom;  // sin coefficient
    const double B = -a * 2 * zeta * omega * big_omega / denom;             // cos coefficient
    const double wd = omega * std::sqrt(1 - zeta * zeta);
    const double c1 = x0 - B;
    const double c2 = (v0 - A * big_omega + zeta * omega * c1) / wd;
    return A * std::sin(big_omega * t) + B * std::cos(big_omega * t) +
           std::exp(-zeta * omega * t) * (c1 * std::cos(wd * t) + c2 * std::sin(wd * t));
  }
};

// The least-squares slope of y against x: a convergence order from log error against log η.
double fitted_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

TEST_CASE("PIM is exact for a forced damped linear oscillator at any step", "[pim]") {
  // One mass with a gap spring it never reaches: the step is exact up to rounding, whatever η.
  const double omega = 1.3, zeta = 0.05, a = 0.7, big_omega = 2.1;
  GapStructure s = single_mass(1.0, 2 * zeta * omega, omega * omega);
  s.springs.push_back({0, -1, 1.0, 50.0, 10.0});
  s.loads.push_back({0, a, big_omega, 0.0});
  const ForcedOscillator exact{omega, zeta, a, big_omega, 0.2, -0.1};
  for (double eta : {0.001, 0.1, 1.0, 5.0}) {
    auto integrator = make_pim_integrator(s, pim(eta));
    integrator->set_state(0.0, Vector::Constant(1, 0.2), Vector::Constant(1, -0.1));
    double worst = 0.0;
    integrator->advance_to(200 * eta > 100 ? 100.0 : 200 * eta, [&](double t, const Vector& x,
                                                                     const Vector&) {
      worst = std::max(worst, std::abs(x[0] - exact.position(t)));
    });
    INFO("eta = " << eta);
    CHECK(worst < 1e-13);
  }
}

TEST_CASE("PIM at undamped resonance grows like the closed-form t sin solution", "[pim]") {
  // x'' + ω² x = F sin ωt from rest: x = F/(2ω²) (sin ωt - ωt cos ωt). (ω²I + H²) is singular
  // here, so the paper's harmonic formula would fail; the doubling recurrences do not.
  const double omega = 2.0, force = 0.3;
  GapStructure s = single_mass(1.0, 0.0, omega * omega);
  s.loads.push_back({0, force, omega, 0.0});
  auto integrator = make_pim_integrator(s, pim(2 * M_PI / omega / 64));
  integrator->set_state(0.0, Vector::Zero(1), Vector::Zero(1));
  double worst = 0.0, largest = 0.0;
  integrator->advance_to(100 * 2 * M_PI / omega, [&](double t, const Vector& x, const Vector&) {
    const double exact =
        force / (2 * omega * omega) * (std::sin(omega * t) - omega * t * std::cos(omega * t));
    worst = std::max(worst, std::abs(x[0] - exact));
    largest = std::max(largest, std::abs(exact));
  });
  CHECK(largest > 20.0);  // it did grow
  CHECK(worst < 1e-12 * largest);
}

TEST_CASE("PIM on a free-free structure (singular stiffness)", "[pim]") {
  // Two masses joined by a spring, nothing to the ground, F sin Ωt on mass 1, from rest.
  // Centre of mass: X'' = F sin Ωt / 2m; stretch r = x1 - x2: r'' + (2k/m) r = (F/m) sin Ωt.
  const double m = 1.5, k = 2.0, F = 0.8, W = 0.9;
  GapStructure s;
  Matrix K(2, 2);
  K << k, -k, -k, k;
  s.mass = to_sparse(m * Matrix::Identity(2, 2));
  s.damping = to_sparse(Matrix::Zero(2, 2));
  s.stiffness = to_sparse(K);
  s.loads.push_back({0, F, W, 0.0});
  // A clearance spring between the masses that is never closed keeps an LCP in every step.
  s.springs.push_back({0, 1, -1.0, 10.0, 5.0});
  auto integrator = make_pim_integrator(s, pim(0.05));
  integrator->set_state(0.0, Vector::Zero(2), Vector::Zero(2));
  const double w2 = 2 * k / m, w = std::sqrt(w2), a = F / (2 * m), f = F / m;
  double worst = 0.0;
  integrator->advance_to(40.0, [&](double t, const Vector& x, const Vector&) {
    const double centre = (a / W) * t - (a / (W * W)) * std::sin(W * t);
    const double stretch = f / (w2 - W * W) * (std::sin(W * t) - (W / w) * std::sin(w * t));
    worst = std::max(worst, std::abs(x[0] - (centre + stretch / 2)));
    worst = std::max(worst, std::abs(x[1] - (centre - stretch / 2)));
  });
  CHECK(worst < 1e-12);
}

TEST_CASE("PIM on a gap oscillator converges at order 2 to the closed-form motion", "[pim]") {
  // x'' + x + α max(0, x) = 0 from x = 0, x' = 1: half a period π on the slack side with
  // amplitude 1, half a period π/√(1+α) on the contact side with amplitude 1/√(1+α).
  const double alpha = 3.0, r = std::sqrt(1 + alpha);
  GapStructure s = single_mass(1.0, 0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, alpha, 0.0});
  const double period = M_PI + M_PI / r;
  auto exact = [&](double t) {
    const double u = std::fmod(t, period);
    return u < M_PI / r ? std::sin(r * u) / r : std::sin(u - M_PI / r) * -1.0;
  };
  // The constant of the error depends on where each kink falls inside its step, so pairwise
  // ratios scatter; the least-squares slope of log error against log η over five halvings is the
  // order.
  std::vector<double> log_eta, log_error;
  for (int steps : {200, 400, 800, 1600, 3200}) {
    auto integrator = make_pim_integrator(s, pim(period / steps));
    integrator->set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
    double worst = 0.0;
    integrator->advance_to(10 * period, [&](double t, const Vector& x, const Vector&) {
      worst = std::max(worst, std::abs(x[0] - exact(t)));
    });
    log_eta.push_back(std::log(period / steps));
    log_error.push_back(std::log(worst));
  }
  const double order = fitted_slope(log_eta, log_error);
  INFO("fitted order " << order);
  CHECK(order > 1.9);
  CHECK(order < 2.1);
  CHECK(std::exp(log_error.back()) < 2e-5);
}

TEST_CASE("PIM on a forced damped gap oscillator converges at order 2 to the reference",
          "[pim]") {
  // x'' + 0.1 x' + x + 4 max(0, x - 0.2) = 0.8 sin(1.3 t): no closed form, so the truth is the
  // kink-located dopri5 at tolerance 1e-12, sampled at the same times.
  GapStructure s = single_mass(1.0, 0.1, 1.0);
  s.springs.push_back({0, -1, 1.0, 4.0, 0.2});
  s.loads.push_back({0, 0.8, 1.3, 0.0});
  const double T = 2 * M_PI / 1.3, horizon = 20 * T;
  ReferenceOptions r;
  r.relative_tolerance = r.absolute_tolerance = 1e-12;
  r.locate_kinks = true;
  auto reference = make_reference_integrator(s, r);
  reference->set_state(0.0, Vector::Zero(1), Vector::Zero(1));
  std::vector<double> truth;  // x at t = k T / 16
  for (int k = 1; k <= 20 * 16; ++k) {
    reference->advance_to(k * T / 16);
    truth.push_back(reference->position()[0]);
  }
  CHECK(reference->stats().kink_events > 20);  // it does touch, often
  std::vector<double> log_eta, log_error;
  for (int steps : {64, 128, 256, 512, 1024}) {
    auto integrator = make_pim_integrator(s, pim(T / steps));
    integrator->set_state(0.0, Vector::Zero(1), Vector::Zero(1));
    double worst = 0.0;
    for (int k = 1; k <= 20 * 16; ++k) {
      integrator->advance_to(k * T / 16);
      worst = std::max(worst, std::abs(integrator->position()[0] - truth[k - 1]));
    }
    CHECK(integrator->time() == Approx(horizon));
    log_eta.push_back(std::log(T / steps));
    log_error.push_back(std::log(worst));
  }
  const double order = fitted_slope(log_eta, log_error);
  INFO("fitted order " << order << ", finest error " << std::exp(log_error.back()));
  CHECK(order > 1.85);
  CHECK(order < 2.15);
  CHECK(std::exp(log_error.back()) < 1e-4);
}

TEST_CASE("PIM conserves energy of an undamped gap chain to second order", "[pim]") {
  NondimensionalChain c = paper_five_dof_case("4a");
  c.zeta = 0.0;
  c.amplitude = {0.0};
  const GapStructure s = make_chain(c);
  const Matrix K = Matrix(s.stiffness);
  auto energy = [&](const Vector& x, const Vector& v) {
    double e = 0.5 * v.squaredNorm() + 0.5 * x.dot(K * x);
    for (const GapSpring& g : s.springs) e += 0.5 * g.stiffness * std::pow(std::max(0.0, x[g.dof] - g.gap), 2);
    return e;
  };
  Vector x0(5), v0(5);
  x0 << 0.3, -0.2, 0.5, 0.1, -0.4;
  v0 << 0.2, 0.1, -0.3, 0.4, 0.0;
  const double e0 = energy(x0, v0);
  std::vector<double> drift;
  for (double eta : {0.04, 0.02, 0.01}) {
    auto integrator = make_pim_integrator(s, pim(eta));
    integrator->set_state(0.0, x0, v0);
    double worst = 0.0;
    integrator->advance_to(200.0, [&](double, const Vector& x, const Vector& v) {
      worst = std::max(worst, std::abs(energy(x, v) - e0));
    });
    drift.push_back(worst / e0);
  }
  CHECK(drift[0] < 1e-2);
  CHECK(std::log2(drift[0] / drift[1]) > 1.7);
  CHECK(std::log2(drift[1] / drift[2]) > 1.7);
}

TEST_CASE("Lemke and block pivoting, fixed and dynamic sizes give one trajectory", "[pim]") {
  const GapStructure five = make_chain(paper_five_dof_case("4b"));
  const double eta = paper_five_dof_case("4b").period() / 200;
  auto a = make_pim_integrator(five, pim(eta, "block-pivoting"));
  auto b = make_pim_integrator(five, pim(eta, "lemke"));
  // The same chain with a seventh, inert mass runs on the dynamic-size path; its first five
  // masses differ (the extra mass loads mass 5), so compare it against itself with both solvers.
  for (auto* i : {a.get(), b.get()}) i->set_state(0.0, Vector::Zero(5), Vector::Zero(5));
  a->advance_to(200 * eta * 50);
  b->advance_to(200 * eta * 50);
  CHECK((a->position() - b->position()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(a->position().cwiseAbs().maxCoeff() > 0.1);  // it moved and touched

  NondimensionalChain seven = paper_five_dof_case("4b");
  seven.masses = 7;
  seven.amplitude = {1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0};
  const GapStructure s7 = make_chain(seven);
  auto c = make_pim_integrator(s7, pim(eta, "block-pivoting"));
  auto d = make_pim_integrator(s7, pim(eta, "lemke"));
  for (auto* i : {c.get(), d.get()}) i->set_state(0.0, Vector::Zero(7), Vector::Zero(7));
  c->advance_to(200 * eta * 50);
  d->advance_to(200 * eta * 50);
  CHECK((c->position() - d->position()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(c->stats().steps == 200 * 50);
}

TEST_CASE("PIM rejects bad input with the field and value named", "[pim]") {
  const GapStructure s = make_chain(paper_five_dof_case("4a"));
  CHECK_THROWS_WITH(make_pim_integrator(s, pim(0.0)), Catch::Contains("step = 0"));
  CHECK_THROWS_WITH(make_pim_integrator(s, pim(-0.1)), Catch::Contains("step = -0.1"));
  CHECK_THROWS_WITH(make_pim_integrator(s, pim(0.1, "simplex")), Catch::Contains("simplex"));
  auto integrator = make_pim_integrator(s, pim(0.1));
  CHECK_THROWS_WITH(integrator->set_state(0.0, Vector::Zero(4), Vector::Zero(5)),
                    Catch::Contains("4 displacements"));
  Vector nan = Vector::Zero(5);
  nan[2] = std::nan("");
  CHECK_THROWS_AS(integrator->set_state(0.0, nan, Vector::Zero(5)), InputError);
  integrator->set_state(0.0, Vector::Zero(5), Vector::Zero(5));
  CHECK_THROWS_WITH(integrator->advance_to(0.25), Catch::Contains("whole"));
  CHECK_THROWS_AS(integrator->advance_to(-0.1), InputError);

  GapStructure bad = s;
  bad.mass.coeffRef(2, 2) = -1.0;
  CHECK_THROWS_WITH(make_pim_integrator(bad, pim(0.1)), Catch::Contains("mass[2,2] = -1"));
  bad = s;
  bad.stiffness.coeffRef(0, 1) = 5.0;
  CHECK_THROWS_WITH(make_pim_integrator(bad, pim(0.1)), Catch::Contains("not symmetric"));
  bad = s;
  bad.springs[3].stiffness = std::nan("");
  CHECK_THROWS_WITH(make_pim_integrator(bad, pim(0.1)), Catch::Contains("springs[3].stiffness"));
}

TEST_CASE("PIM reports motion that blows up", "[pim]") {
  // Undamped resonance with a small divergence bound.
  GapStructure s = single_mass(1.0, 0.0, 1.0);
  s.loads.push_back({0, 1.0, 1.0, 0.0});
  PimOptions o = pim(0.1);
  o.divergence_bound = 5.0;
  auto integrator = make_pim_integrator(s, o);
  integrator->set_state(0.0, Vector::Zero(1), Vector::Zero(1));
  CHECK_THROWS_AS(integrator->advance_to(1000.0), DivergenceError);
  CHECK(integrator->time() < 100.0);
}

TEST_CASE("The PIM tangent map is the Jacobian of the step map", "[pim][tangent]") {
  // Over one forcing period of the period-7 case (many contacts), the product of the step
  // Jacobians matches central differences of the map itself. The map is piecewise affine, so
  // differences with a perturbation that keeps every active set agree to rounding.
  const NondimensionalChain c = paper_five_dof_case("4b");
  const GapStructure s = make_chain(c);
  const double T = c.period(), eta = T / 200;
  auto run = make_pim_integrator(s, pim(eta));
  run->set_state(0.0, Vector::Zero(5), Vector::Zero(5));
  run->advance_to(100 * T);  // onto the attractor
  const Vector x0 = run->position(), v0 = run->velocity();
  Matrix tangent = Matrix::Identity(10, 10);
  run->advance_with_tangent(101 * T, tangent);
  const Vector end_x = run->position();

  auto image = [&](const Vector& state) {
    auto i = make_pim_integrator(s, pim(eta));
    i->set_state(100 * T, state.head(5), state.tail(5));
    i->advance_to(101 * T);
    Vector out(10);
    out << i->position(), i->velocity();
    return out;
  };
  Vector base(10);
  base << x0, v0;
  // The restart reproduces the run (time counted from another origin rounds differently).
  CHECK((image(base).head(5) - end_x).norm() < 1e-12);
  const double h = 1e-7;
  Matrix differences(10, 10);
  for (int j = 0; j < 10; ++j) {
    Vector plus = base, minus = base;
    plus[j] += h;
    minus[j] -= h;
    differences.col(j) = (image(plus) - image(minus)) / (2 * h);
  }
  INFO("tangent:\n" << tangent << "\ndifferences:\n" << differences);
  CHECK((tangent - differences).cwiseAbs().maxCoeff() < 1e-6 * tangent.cwiseAbs().maxCoeff());
  CHECK(tangent.cwiseAbs().maxCoeff() > 1e-3);  // not trivially zero
}

TEST_CASE("Without contacts the tangent map is exp(H t)", "[pim][tangent]") {
  GapStructure s = single_mass(2.0, 0.3, 5.0);
  s.springs.push_back({0, -1, 1.0, 10.0, 100.0});
  s.loads.push_back({0, 1.0, 1.1, 0.0});
  auto run = make_pim_integrator(s, pim(0.05));
  run->set_state(0.0, Vector::Zero(1), Vector::Zero(1));
  Matrix tangent = Matrix::Identity(2, 2);
  run->advance_with_tangent(10.0, tangent);
  // For x'' + 0.15 x' + 2.5 x = f: the determinant of exp(H t) is exp(trace(H) t) = exp(-0.15 t).
  CHECK(tangent.determinant() == Approx(std::exp(-0.15 * 10.0)).epsilon(1e-12));
  // The eigenvalues are exp(λ t) with λ = -0.075 ± i sqrt(2.5 - 0.075²): modulus exp(-0.75).
  const Eigen::VectorXcd mu = tangent.eigenvalues();
  CHECK(std::abs(mu[0]) == Approx(std::exp(-0.75)).epsilon(1e-12));
  CHECK(std::abs(mu[1]) == Approx(std::exp(-0.75)).epsilon(1e-12));
}
