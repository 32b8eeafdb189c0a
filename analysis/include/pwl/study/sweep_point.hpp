#pragma once
// One point of a parameter study: the nondimensional chain at one parameter value, integrated from
// a given state past its transient, its stroboscopic Poincaré points recorded and its motion
// classified.
//
// A bifurcation diagram or a regime map evaluates thousands of these, so a point keeps only what
// the study needs: the Poincaré points of the chosen state components, a handful of numbers (the
// regime, its period, λ1 and K of the 0-1 test) and the final state, from which the next point of
// a continuation starts. The trajectory between Poincaré points is never stored.
//
// The result depends only on the chain, the initial state and the settings: no clock, no thread,
// no random seed that is not fixed here. That is what makes a serial, a multithreaded, a
// distributed and a resumed study write identical files.
#include <limits>
#include <string>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/types.hpp"

namespace pwl::analysis {

// The parameter of a NondimensionalChain a study varies.
enum class SweepParameter {
  theta,      // forcing frequency ratio θ
  alpha,      // contact stiffness ratio α of every mass
  zeta,       // damping ratio ζ
  gap,        // gap Δ̃ of every mass
  amplitude,  // load scale: Q = value · (the base chain's Q)
};

// "theta", "alpha", "zeta", "gap", "amplitude".
std::string parameter_name(SweepParameter parameter);
// The inverse; also accepts "delta" for the gap. Throws InputError naming the value otherwise.
SweepParameter parse_sweep_parameter(const std::string& name);
// A copy of `base` with the parameter set to `value`.
NondimensionalChain with_parameter(const NondimensionalChain& base, SweepParameter parameter,
                                   double value);

struct PointSettings {
  int transient_periods = 500;  // forcing periods integrated and discarded (>= 0)
  int recorded_periods = 500;   // Poincaré points recorded and classified (>= 1)
  int steps_per_period = 200;   // PIM steps per forcing period, η = T / steps_per_period
  // 0-based state components kept in PointResult::poincare: 0..n-1 are x1..xn, n..2n-1 are
  // v1..vn. May be empty (a regime map keeps only the classification).
  std::vector<int> components;
  int observable = -1;     // component the 0-1 test reads; -1: x of the last mass
  bool lyapunov = true;    // λ1 from the exact tangent map of the PIM step
  std::string method = "pim";  // "pim", or "dopri5" (kink-located; λ1 is then not computed)
  double tolerance = 1e-10;    // dopri5's relative and absolute tolerance

  // Ceres-style check for a chain of `masses` masses: false with a message naming the field.
  bool is_valid(int masses, std::string* why) const;
};

struct PointResult {
  std::string regime;  // regime_name(...) of the classifier, or "failed" (an unsolvable LCP)
  int period = 0;      // k for period-k, 0 otherwise
  double lambda1 = std::numeric_limits<double>::quiet_NaN();  // per forcing period; NaN: none
  double lambda1_error = std::numeric_limits<double>::quiet_NaN();
  double K = std::numeric_limits<double>::quiet_NaN();  // 0-1 test; NaN when not computed
  int columns = 0;              // = settings.components.size()
  std::vector<double> poincare; // recorded points x columns, row-major
  Vector final_state;           // [x; v] at the end; empty when the motion blew up or failed

  int rows() const { return columns == 0 ? 0 : static_cast<int>(poincare.size()) / columns; }
};

// A small integer per regime for colour maps and legends: 1..8 period-k, 9 a longer period,
// 10 quasi-periodic, 11 chaotic, 12 unbounded, 13 uncertain or failed.
int regime_code(const std::string& regime, int period);

// Integrates `chain` from `initial_state` ([x; v], 2n; the loads start at phase 0) over
// transient_periods + recorded_periods forcing periods and classifies the recorded ones: the period
// search on the full state, λ1 over the recorded periods (from one tangent vector renormalised
// every period; the first min(50, recorded/5) periods align it), and K on the observable when at
// least 100 points are recorded. A motion that blows up is "unbounded" (not an exception).
// Throws InputError for invalid settings or state.
PointResult evaluate_point(const NondimensionalChain& chain, const Vector& initial_state,
                           const PointSettings& settings);

}  // namespace pwl::analysis
