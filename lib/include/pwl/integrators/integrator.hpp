#pragma once
// The one concept every time integrator of pwl models (after Boost.Odeint's stepper concept):
// it holds a state (t, x, x') of a GapStructure and advances it to a requested time, telling an
// observer about every step it takes. The precise-integration stepper and the Runge-Kutta
// reference integrators are interchangeable behind it, so analysis code never knows which one
// produced the motion it studies.
#include <functional>
#include <memory>
#include <string>

#include "pwl/integrators/method.hpp"
#include "pwl/types.hpp"

namespace pwl {

// Called after every internal step with the time and the state at the end of the step. The
// references are valid only during the call: copy what you keep.
using StepObserver = std::function<void(double t, const Vector& x, const Vector& v)>;

struct IntegratorStats {
  long steps = 0;            // accepted steps
  long rejected_steps = 0;   // adaptive integrators: steps redone with a smaller size
  long rhs_evaluations = 0;  // adaptive integrators: right-hand-side calls
  long kink_events = 0;      // spring openings/closings located (kink-located integrators)
  long lcp_pivots = 0;       // precise integration: LCP pivots summed over the steps
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // A description for messages and tables, with the integrator's settings ("pim (step 0.0314,
  // block-pivoting)"). For people only: code asks method() and its row of the method table.
  virtual std::string name() const = 0;
  // Which method of the method table this is (for a method that chooses its dense or banded form,
  // the form it took).
  virtual Method method() const = 0;
  virtual Index dofs() const = 0;
  // Sets time, displacements and velocities (the spring forces follow from x).
  virtual void set_state(double t, const Vector& x, const Vector& v) = 0;
  virtual double time() const = 0;
  virtual const Vector& position() const = 0;
  virtual const Vector& velocity() const = 0;
  // Integrates to exactly t_end (>= time()). Fixed-step integrators require t_end to lie on
  // their step grid and throw InputError otherwise. Throws DivergenceError when the state stops
  // being finite or leaves the integrator's divergence bound.
  virtual void advance_to(double t_end, const StepObserver& observer = nullptr) = 0;
  virtual IntegratorStats stats() const = 0;

  // Advances to t_end like advance_to and multiplies `tangent` (2n x p, rows in state order
  // [x; x']) by the Jacobian of the motion from time() to t_end, for Lyapunov exponents and
  // Floquet multipliers. Integrators without an exact tangent map throw InputError; the default
  // is that.
  virtual void advance_with_tangent(double t_end, Matrix& tangent,
                                    const StepObserver& observer = nullptr);
  // Whether advance_with_tangent is implemented (false: it throws): the tangent_map column of this
  // method's row of the method table.
  bool has_tangent_map() const;

  // Tangent replay. The tangent map of a piecewise-linear motion is a product of linear maps that
  // the base motion fixes (its modes, the times of its switches, its active sets). An integrator
  // that can record them while advance_with_tangent runs applies them again to other columns
  // without integrating the state, so that many products with one monodromy (the Krylov products
  // of Newton-Krylov shooting, Arnoldi's) cost only the tangent's own arithmetic, which on a long
  // chain full of contacts is a fraction of the step's (the switch search is not repeated). The
  // replayed columns equal what advance_with_tangent gives them, to the last bit.
  //
  // Recording is off by default: the record grows with the run. While it is on, set_state starts
  // a new record, each advance_with_tangent or advance_to extends it (the motion fixes the
  // tangent map whether or not tangent columns ride along), and a run that throws ends it.
  // Integrators without it answer false and ignore record_tangent(false).
  virtual bool can_record_tangent() const { return false; }
  // Throws InputError when asked to record without can_record_tangent().
  virtual void record_tangent(bool on);
  // Applies the tangent map of the motion from the last set_state to time(), as recorded, to
  // `tangent` (2n x p); leaves the state alone. False (and `tangent` untouched) when there is no
  // complete record: recording off, a run that threw since set_state, or a record that outgrew
  // its limit.
  virtual bool replay_tangent(Matrix& tangent);
};

}  // namespace pwl
