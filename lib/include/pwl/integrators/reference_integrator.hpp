#pragma once
// Reference integrators: Boost.Odeint's embedded Runge-Kutta pairs on the continuous right-hand
// side  x'' = M^{-1} (f(t) - C x' - K x - W k max(0, W^T x - Δ)).
//
// Two variants. "Plain" integrates across the kinks of the spring force the way MATLAB's ode45
// does, so its error control sees the jump in the force's slope only through rejected steps.
// "Kink-located" never lets a step straddle a kink: after each accepted step it looks for a sign
// change of any gap function g_j, locates the earliest crossing (on dopri5's dense output, or by
// a root search on the one-step map for rkf78) and redoes the step so that it ends exactly there.
// Each step then sees a smooth right-hand side and the method keeps its nominal order.
//
// Method references: Dormand & Prince, J. Comput. Appl. Math. 6 (1980) 19-26 (dopri5);
// Fehlberg, NASA TR R-287 (1968) (rkf78); event location as in Hairer, Nørsett & Wanner,
// Solving ODEs I, §II.6 (dense output) and Shampine & Thompson, "Event location for ordinary
// differential equations", Comput. Math. Appl. 39 (2000) 43-54.
#include <memory>
#include <string>

#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/integrator.hpp"

namespace pwl {

enum class RungeKuttaMethod { dopri5, rkf78 };

struct ReferenceOptions {
  RungeKuttaMethod method = RungeKuttaMethod::dopri5;
  double relative_tolerance = 1e-10;
  double absolute_tolerance = 1e-10;
  bool locate_kinks = false;
  double max_step = 0.0;           // 0: no limit
  double initial_step = 1e-3;      // first trial step
  double divergence_bound = 1e12;  // |x|, |x'| beyond this is a DivergenceError
  // Ceres-style check: false with a message naming the field and value.
  bool is_valid(std::string* why) const;
};

// Throws InputError for an invalid structure or options.
std::unique_ptr<Integrator> make_reference_integrator(const GapStructure& structure,
                                                      const ReferenceOptions& options);

// "dopri5" | "rkf78", for command lines. Throws InputError otherwise.
RungeKuttaMethod parse_runge_kutta_method(const std::string& name);

}  // namespace pwl
