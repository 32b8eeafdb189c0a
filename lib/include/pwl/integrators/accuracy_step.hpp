#pragma once
// The step a fixed-grid method (the PIM family) needs for a requested accuracy: the user asks for
// an error, pwl finds the cheapest step that meets it.
//
// A fixed step has no error control of its own, and the error of a step depends on the structure
// (its stiffest contact, how often springs switch) as much as on the step. So the step is found
// the way an adaptive method would find it, but once, on a probe stretch of the motion: from the
// largest step the step guard lets through without a warning (η ω_max at the method's
// step_warning, step_guard.hpp), each candidate η = T/N is integrated over the probe together
// with η/2, and the error of η is estimated by step doubling as 2 max |y_η - y_{η/2}| at the
// common grid points (Richardson: for a method of order p the error of η is
// 2^p/(2^p - 1) |y_η - y_{η/2}| asymptotically, at most twice it for any p >= 1, so the factor 2
// holds for the plain PIM, whose error is first order where springs switch inside a step, and for
// the switching PIM's order d + 3 alike). The error is relative: the largest difference of the
// positions over the largest position of the probe, and the same for the velocities, the larger
// of the two. A candidate that misses the tolerance gives the next one from the same estimate
// (η (0.8 rtol / E)^{1/p}, p the method's order, and at least a tenth shorter: an estimate
// outside its asymptotic range can promise too much), until one meets it.
//
// The switching PIM's force degree can be chosen too (AccuracyRequest::force_degrees): the
// degrees are tried from the highest, whose order lets the largest step through; the step it
// finds is then tried with the next lower degree, which is kept when it meets the tolerance
// there too (a smooth step's series has d + 1 terms, so at one step the lower degree is the
// cheaper), and so on down until one misses. On the paper's 1000-mass chain a run at one step
// costs about the same at d = 2, 4 and 6 (the switching steps, redone on the series to rounding
// whatever d, dominate), while d = 6 at η = 0.4 s (4.4e-9 in x1) is more accurate than d = 2 at
// 0.08 s (1.3e-8) and costs less than its 5x more steps.
//
// What the estimate covers: the probe only (the caller picks it, e.g. the first few forcing
// periods of the run); an error that grows along a long run (a chaotic motion, a slowly drifting
// phase) is not foreseen. Where the tolerance is below what the method reaches on the structure
// (rounding, or max_steps_per_period), it throws InputError saying the best estimate found.
//
// Hairer, Nørsett & Wanner, Solving ODEs I, §II.4 (step doubling, Richardson extrapolation).
#include <array>
#include <string>
#include <vector>

#include "pwl/integrators/method_table.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/types.hpp"

namespace pwl {

// Below this a request is refused outright: the rounding of thousands of steps in double
// precision (the switching PIM's errors stop falling near 1e-13).
inline constexpr double kSmallestRelativeTolerance = 1e-12;

// The switching PIM's force degrees an accuracy request chooses from when the user fixes none
// (`--rtol`, the benchmarks' accuracy rows).
inline constexpr std::array<int, 3> kChoosableForceDegrees{2, 4, 6};

struct AccuracyRequest {
  double relative_tolerance = 0.0;    // in [1e-12, 1): the largest relative error on the probe
  double period = 0.0;                // > 0: the step divides it (an integer number of steps)
  double probe = 0.0;                 // > 0: the stretch of motion the estimate is made on (s)
  long max_steps_per_period = 1L << 20;
  // The switching PIM only: the force degrees d (0 .. 8) to choose from, as above. Empty: the
  // base settings' degree.
  std::vector<int> force_degrees;
  // Ceres-style check: false with a message naming the field and its value.
  bool is_valid(std::string* why) const;
};

struct AccuracyStep {
  long steps_per_period = 0;
  double step = 0.0;             // period / steps_per_period
  double estimated_error = 0.0;  // of that step on the probe, relative
  double largest_step = 0.0;     // the step guard's largest step without a warning
  int candidates = 0;            // steps tried (each integrated over the probe twice)
  int force_degree = -1;         // the switching PIM's degree for that step; -1: not one
  int degree_checks = 0;         // lower degrees tried at the chosen step (twice each, too)
};

// The largest step T/N (N from the step guard's largest step up) whose estimated error on the
// probe, from (t0, x0, v0), meets the request, for the fixed-grid method of `base` (its step is
// ignored), and with force_degrees its degree. Throws InputError for an invalid request, a
// method without a fixed grid (the adaptive ones take a tolerance of their own), degrees for a
// method that takes none, and a tolerance the method does not reach.
AccuracyStep step_for_accuracy(const GapStructure& structure, const MethodSettings& base,
                               double t0, const Vector& x0, const Vector& v0,
                               const AccuracyRequest& request);

}  // namespace pwl
