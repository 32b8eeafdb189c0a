#pragma once
// Structures and independent computations the periodic-orbit tests (tests/orbits) share: the
// single gap oscillator built by hand, the state matrix of one contact state, the contact events
// of the exact solver along a stretch of motion, and the state of an integrator.
#include <Eigen/LU>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/point_model.hpp"
#include "test_structures.hpp"

namespace pwl::test {

// A measured number, printed when PWL_TEST_VERBOSE is set (the tests' margins at a glance; Catch
// prints small doubles in fixed notation).
inline void measured(const std::string& what, double value) {
  if (std::getenv("PWL_TEST_VERBOSE") != nullptr)
    std::printf("measured %s: %.3e\n", what.c_str(), value);
}

// The state [x; x'] of an integrator.
inline Vector state_of(const Integrator& integrator) {
  Vector y(2 * integrator.dofs());
  y << integrator.position(), integrator.velocity();
  return y;
}

// One mass of the nondimensional chain, its gap spring to the ground: x'' + 2ζ x' + x + α max(0,
// x − Δ̃) = Q sin(θ t).
inline NondimensionalChain one_mass(double alpha, double zeta, double gap, double amplitude,
                                    double theta) {
  NondimensionalChain c;
  c.masses = 1;
  c.alpha = {alpha};
  c.zeta = zeta;
  c.gap = {gap};
  c.amplitude = {amplitude};
  c.theta = theta;
  return c;
}

// The hardening gap oscillator of the continuation-sweep test (tests/study/parameter_sweep_test):
// one mass of the nondimensional chain, α = 3, ζ = 0.1, Δ̃ = 1.5, Q = 0.5; its resonance bends to
// higher θ once the mass reaches the gap, with two folds and hysteresis between them.
// One of the paper's 5-DOF cases ("4a", "4b", "5", "6") at the forcing frequency θ.
inline NondimensionalChain paper_case_at(const std::string& figure, double theta) {
  NondimensionalChain c = paper_five_dof_case(figure);
  c.theta = theta;
  return c;
}

inline NondimensionalChain hardening_oscillator(double theta) {
  return one_mass(3.0, 0.1, 1.5, 0.5, theta);
}

// The undamped linear resonance of the chain's one mass (α = 0, ζ = 0, Q = 1, θ = 1): its amplitude
// grows like t from every initial state.
inline NondimensionalChain undamped_resonance() { return one_mass(0.0, 0.0, 0.0, 1.0, 1.0); }

// x'' + 2ζ x' + x + α max(0, x − Δ) = q sin(θ t): one unit mass, one gap spring to the ground.
struct GapOscillator {
  double zeta = 0.05;
  double alpha = 1.5;
  double gap = 0.6;
  double q = 0.3;
  double theta = 0.8;

  double period() const { return 2 * M_PI / theta; }
  GapStructure structure() const {
    GapStructure s = single_mass(1.0, 2 * zeta, 1.0);
    s.springs.push_back({0, -1, 1.0, alpha, gap});
    s.loads.push_back({0, q, theta, 0.0});
    return s;
  }
  analysis::PointCase point_case() const { return {structure(), period()}; }
};

// H_A = [[0, I], [−M⁻¹(K + W_A k_A W_A^T), −M⁻¹C]]: the state matrix with the springs in `active`
// touching (every spring slack when it is empty).
inline Matrix state_matrix(const GapStructure& s, const std::vector<int>& active = {}) {
  const Index n = s.dofs();
  const Matrix mass = Matrix(s.mass);
  Matrix K = Matrix(s.stiffness);
  const Matrix W = s.spring_directions();
  for (int j : active) K += s.springs[j].stiffness * W.col(j) * W.col(j).transpose();
  Matrix H = Matrix::Zero(2 * n, 2 * n);
  H.topRightCorner(n, n).setIdentity();
  H.bottomLeftCorner(n, n) = -mass.lu().solve(K);
  H.bottomRightCorner(n, n) = -mass.lu().solve(Matrix(s.damping));
  return H;
}

// [x(0); x'(0)] of the steady response of the structure with every spring open to its loads, all
// of one frequency ω (each a sin(ωt + φ)): X = (K − ω²M + iωC)⁻¹ F, x(t) = Im(X e^{iωt}).
inline Vector harmonic_response(const GapStructure& s, double omega) {
  using Complex = std::complex<double>;
  const Index n = s.dofs();
  const Eigen::MatrixXcd Z =
      (Matrix(s.stiffness) - omega * omega * Matrix(s.mass)).cast<Complex>() +
      Complex(0, omega) * Matrix(s.damping).cast<Complex>();
  Eigen::VectorXcd F = Eigen::VectorXcd::Zero(n);
  for (const HarmonicLoad& load : s.loads)
    F(load.dof) += load.amplitude * std::polar(1.0, load.phase);
  const Eigen::VectorXcd X = Z.partialPivLu().solve(F);
  Vector y(2 * n);
  y.head(n) = X.imag();
  y.tail(n) = omega * X.real();
  return y;
}

struct ContactEvent {
  double t;
  Index spring;
  bool touching;
};

// The spring switches of the exact solver's motion from state y at t0 to t1.
inline std::vector<ContactEvent> contact_events(const GapStructure& s, const Vector& y, double t0,
                                                double t1) {
  EventDrivenSolver solver(s);
  std::vector<ContactEvent> events;
  solver.set_event_observer([&](double t, Index spring, bool touching) {
    events.push_back({t, spring, touching});
  });
  const Index n = s.dofs();
  solver.set_state(t0, y.head(n), y.tail(n));
  solver.advance_to(t1);
  return events;
}

// The largest distance from each value of `expected` to the nearest of `actual` (and 1e300 when
// the sizes differ): multipliers compared as sets.
inline double set_distance(const std::vector<std::complex<double>>& expected,
                           const std::vector<std::complex<double>>& actual) {
  if (expected.size() != actual.size()) return 1e300;
  double worst = 0;
  for (const auto& e : expected) {
    double best = 1e300;
    for (const auto& a : actual) best = std::min(best, std::abs(a - e));
    worst = std::max(worst, best);
  }
  for (const auto& a : actual) {
    double best = 1e300;
    for (const auto& e : expected) best = std::min(best, std::abs(a - e));
    worst = std::max(worst, best);
  }
  return worst;
}

// The values of `all` (every multiplier, from a formed monodromy) of modulus above 1 − margin,
// counted into *in_band, and the largest distance from one of them to the nearest of `reported`
// (0 when there are none): whether a leading set covers the band it was asked for.
inline double farthest_in_band(const std::vector<std::complex<double>>& all,
                               const std::vector<std::complex<double>>& reported, double margin,
                               std::size_t* in_band) {
  *in_band = 0;
  double farthest = 0;
  for (const std::complex<double>& mu : all) {
    if (std::abs(mu) <= 1.0 - margin) continue;
    ++*in_band;
    double nearest = 1e300;
    for (const std::complex<double>& f : reported) nearest = std::min(nearest, std::abs(f - mu));
    farthest = std::max(farthest, nearest);
  }
  return farthest;
}

// The Jacobian of φ_{kT} at y by central differences of the map's flow alone (no tangent map), with
// step h on every component; with `richardson`, the extrapolation (4 D(h/2) − D(h)) / 3, whose
// error is O(h⁴) instead of O(h²).
inline Matrix central_differences(orbits::StroboscopicMap& map, const Vector& y, int periods,
                                  double h, bool richardson) {
  const auto differences = [&](double step) {
    Matrix J(y.size(), y.size());
    for (Index c = 0; c < y.size(); ++c) {
      Vector plus = y, minus = y;
      plus(c) += step;
      minus(c) -= step;
      J.col(c) = (map.advance(plus, periods) - map.advance(minus, periods)) / (2 * step);
    }
    return J;
  };
  const Matrix coarse = differences(h);
  if (!richardson) return coarse;
  return (4 * differences(h / 2) - coarse) / 3;
}

// The stroboscopic points of `count` forcing periods after `transient` ones from y.
inline std::vector<Vector> poincare_points(orbits::StroboscopicMap& map, Vector y, int transient,
                                           int count) {
  if (transient > 0) y = map.advance(y, transient);
  std::vector<Vector> points;
  for (int i = 0; i < count; ++i) {
    y = map.advance(y, 1);
    points.push_back(y);
  }
  return points;
}

}  // namespace pwl::test
