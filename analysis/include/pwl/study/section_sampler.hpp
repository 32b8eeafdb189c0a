#pragma once
// An integrator driven through a Poincaré section (pwl/analysis/poincare_section.hpp): to the
// stroboscopic times t = (k + phase) T, and along every step while the crossings of a hyperplane
// are recorded. `pwl simulate` and the study pipeline (sweep_point.hpp, which evaluates every
// point of `pwl analyze`, `pwl sweep` and `pwl map`) both integrate through it, so every job
// samples a section the same way, with the one interpolation of poincare_section.hpp.
//
// Stroboscopic times. A method that can end a step anywhere (adaptive, exact) is integrated to
// the strobe time itself. A fixed-grid method ends only on its grid t0 + j η (η = T / steps per
// period): a strobe time on the grid (phase 0, or any phase that is a whole number of steps, such
// as 0.25 at T/200) is landed on too, bit for bit the same call as an integration to kT. Any other
// phase falls between two grid points: the integrator is advanced to the grid point before it and
// to the one after it, and the state in between is the cubic Hermite interpolant on (x, v) and
// (v, a) (interpolate_state), with a from the equations of motion. That interpolation errs by
// O(η^4) (O(η^3) over a step in which a spring switches, where a has a kink), below the PIM's own
// O(η^2); integrating to the exact time instead would need a step of another size and the
// exponential that goes with it, which a fixed-grid stepper does not have. The integrator then
// rests at the grid point after the strobe time, and a tangent matrix pushed along covers the
// grid points, one whole period from one strobe to the next, which is what λ1 averages.
//
// Hyperplane crossings. While recording, every step the integrator reports is a sample
// (t, [x; v]) with its time derivative [v; a], and each step is searched for a crossing by
// find_crossing on the Hermite interpolant (a crossing and re-crossing within one step is found
// too; at most the earliest wanted one per step). The samples are the method's steps: every step
// of a fixed-grid method, every accepted step of an adaptive one. The exact solver reports only
// its contact events and the ends of its integrations, so a method that is not on a fixed grid is
// integrated in pieces of at most T / steps_per_period while crossings are recorded: the exact
// solver's states are then exact at least that often, and the crossing times err by the
// interpolation's O(h^4) alone. Recording costs one solve with M per step (the accelerations).
#include <Eigen/SparseCholesky>
#include <functional>
#include <vector>

#include "pwl/analysis/poincare_section.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/types.hpp"

namespace pwl::analysis {

// The accelerations of a GapStructure, a = M⁻¹ (f(t) − C v − K x − W P(x)) with the spring forces
// P = k max(0, W^T x − Δ): the time derivative of the velocities, for Hermite interpolation of
// them. M is factored once (sparse Cholesky).
class StateRate {
 public:
  // Keeps a reference to `structure`, which must outlive it. Throws InputError when M is not
  // positive definite.
  explicit StateRate(const GapStructure& structure);
  Vector acceleration(double t, const Vector& x, const Vector& v) const;

 private:
  const GapStructure& structure_;
  Eigen::SimplicialLDLT<SparseMatrix> mass_;
  SparseMatrix directions_;  // W
};

// A stroboscopic point: its time and the state [x; v] there.
struct StrobePoint {
  double t = 0.0;  // the integrator's time when it landed on the point, else (k + phase) T
  Vector state;
  bool interpolated = false;  // between two grid points of a fixed-grid method
};

class SectionSampler {
 public:
  // Told about every crossing of the hyperplane, in the order of time; the crossing's state is
  // the full [x; v].
  using CrossingSink = std::function<void(const Crossing& crossing)>;

  // `integrator` is at its initial state; its time then is the origin of its step grid and of the
  // strobe times (k + phase) T counted from it. `method` is what it was built from (the step of a
  // fixed grid); `steps_per_period` bounds the spacing of the samples of a method that is not on a
  // fixed grid while crossings are recorded. `integrator` and `structure` must outlive the
  // sampler. Throws InputError for an invalid section or a period that is not positive.
  SectionSampler(Integrator& integrator, const GapStructure& structure, double period,
                 const PoincareSection& section, const MethodSettings& method,
                 int steps_per_period);

  const PoincareSection& section() const { return section_; }
  // The strobe time of index k: origin + (k + phase) T (k T exactly as `k * period` at phase 0).
  double strobe_time(long k) const;
  // Advances to the strobe time of index k (not before the integrator's time, as above) and
  // returns the state there; `tangent` (2n x p, or null) is multiplied by the Jacobian of the
  // motion integrated, `steps` sees every step.
  StrobePoint advance_to_strobe(long k, Matrix* tangent = nullptr,
                                const StepObserver& steps = nullptr);
  // Advances to t_end (on the grid for a fixed-grid method), as Integrator::advance_to and
  // advance_with_tangent, recording crossings on the way when asked to.
  void advance_to(double t_end, Matrix* tangent = nullptr, const StepObserver& steps = nullptr);
  // From the integrator's current state on, every crossing of the section's hyperplane goes to
  // `sink` (an empty sink stops the recording). Throws InputError for a stroboscopic section.
  void record_crossings(CrossingSink sink);

 private:
  void advance_piece(double t_end, Matrix* tangent, const StepObserver& observer);
  void observe(double t, const Vector& x, const Vector& v);
  StateSample sample() const;

  Integrator& integrator_;
  double period_;
  PoincareSection section_;
  StateRate rate_;
  double origin_;
  bool fixed_grid_;
  double step_;         // η of a fixed grid
  double sample_step_;  // the largest piece of a method not on a fixed grid while recording
  CrossingSink sink_;
  // The previous sample of the crossing search: time, state and its derivative.
  double last_t_ = 0.0;
  Vector last_state_;
  Vector last_rate_;
  Vector state_;  // scratch: the current sample
  Vector rate_of_state_;
};

}  // namespace pwl::analysis
