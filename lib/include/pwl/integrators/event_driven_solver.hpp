#pragma once
// The exact event-driven solver: the ground truth of pwl for small structures (up to a few tens
// of degrees of freedom).
//
// While the set A of touching springs is fixed the structure is linear,
//
//     M x'' + C x' + (K + W_A K2_A W_A^T) x = f(t) + W_A K2_A Δ_A,
//
// with harmonic (and constant) loads, so its motion is known in closed form. The solver follows
// the motion from one switch of a spring to the next:
//
//  1. Mode. For each active set met, the state matrix H_A = [[0, I], [-M⁻¹K_A, -M⁻¹C]] is
//     diagonalised, H_A = V Λ V⁻¹, and the motion is x(t) = Re[V (c ⊙ e^{Λ(t - t0)})] plus the
//     particular response to each load frequency, Re[(iωI - H_A)⁻¹ β_ω e^{iωt}], which is
//     computed in the modal coordinates as β̃_k / (iω - λ_k). Any time costs a few complex
//     exponentials, and every derivative of every gap function is a closed-form sum too. Modes
//     are cached by active set.
//  2. Defective and near-defective modes. The modal form is only as accurate as V is well
//     conditioned, and it breaks down where λ_k = iω (undamped resonance: the response grows
//     like t sin ωt) or λ_k = 0 with a constant load (a free-free structure: the rigid-body
//     mode is a Jordan block). When cond(V) exceeds max_eigenvector_condition, or some
//     |iω - λ_k| is below resonance_tolerance times the spectral scale, the mode is represented
//     instead by the exponential of the augmented block-triangular matrix that carries the loads
//     as extra states (sin ωt, cos ωt and 1 obey a linear system themselves; Van Loan 1978):
//     w' = Ĥ_A w, w(t) = exp(Ĥ_A (t - t_a)) w(t_a), with exp by the 2^N algorithm of
//     precise_exponential.hpp. It is exact in every case (Jordan blocks, resonance, singular
//     stiffness) and costs one exponential per distinct time offset, cached; derivative bounds
//     come from the logarithmic norm of Ĥ_A. We chose the eigen-decomposition as the first
//     choice because it makes the root search cheap, and the augmented exponential as the
//     fallback because it needs no assumption at all; `representation` forces either.
//  3. Events. The switching times are found by the safeguarded root search of
//     event_location (a second-derivative bound from the closed form makes it impossible to
//     step over a grazing contact; Newton safeguarded by bisection refines each crossing to a
//     few units in the last place). At an event the crossing springs change mode; the state is
//     continuous (the spring force is continuous in x) and becomes the start of the next mode.
//     Simultaneous crossings switch together. A spring that leaves its kink is given the mode
//     on the side its first non-zero derivative points to (at the kink the force of the spring
//     itself vanishes, so these derivatives do not depend on its own mode); this also settles
//     a start from rest exactly at the kinks, where g = g' = g'' = 0.
//
// The solver models the Integrator concept; advance_to lands exactly on t_end and the observer
// is called at every event and at t_end.
//
// Tangent map. advance_with_tangent multiplies a tangent matrix by the Jacobian of the flow, the
// product over the segments between events of exp(H_A Δt) (loads do not enter it), applied as
// the solver passes each event: Re(V e^{ΛΔt} (V⁻¹ Y)) for a modal mode, the 2^N exponential of
// H_A (the top-left block of exp(Ĥ_A Δt)) otherwise; p columns cost a few 2n x 2n by 2n x p
// products per segment. There is no jump term at a switch: the saltation matrix
// S = I + (f⁺ - f⁻) n^T / (n^T f⁻) (R. I. Leine and H. Nijmeijer, Dynamics and Bifurcation of
// Non-Smooth Mechanical Systems, Springer 2004, ch. 7; M. di Bernardo et al., Piecewise-smooth
// Dynamical Systems, Springer 2008) is the identity because the spring force
// k max(0, g) is continuous in x, so f⁺ = f⁻ on the switching surface. This is the derivative
// at transversal crossings; near a grazing contact the Jacobian varies non-smoothly with the
// state, and for a state resting on a kink (g = g' = 0) it is the one-sided Jacobian of the
// modes the solver took.
//
// Literature: the closed-form event-driven treatment of piecewise-linear oscillators follows
// S. W. Shaw and P. J. Holmes, "A periodically forced piecewise linear oscillator", J. Sound
// Vib. 90 (1983) 129-155, and the numerical event-driven simulation of non-smooth systems
// surveyed by V. Acary and B. Brogliato, Numerical Methods for Nonsmooth Dynamical Systems
// (Springer 2008), ch. 7; event location after L. F. Shampine and S. Thompson, Comput. Math.
// Appl. 39 (2000) 43-54, and E. Hairer, S. P. Nørsett and G. Wanner, Solving ODEs I, §II.6;
// the augmented exponential after C. F. Van Loan, IEEE TAC 23 (1978) 395-404.
#include <functional>
#include <memory>
#include <string>

#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

struct EventDrivenOptions {
  // "auto": modal where it is accurate, augmented exponential otherwise; "modal" (throws
  // InputError for a mode it cannot represent accurately); "exponential".
  std::string representation = "auto";
  // The modal form is used only when cond(V) <= this (1-norm, estimated from the LU factors of
  // V): its rounding is about cond(V) · eps.
  double max_eigenvector_condition = 1e5;
  // |iω - λ_k| (or |λ_k| for a constant load) below this times the spectral scale is resonance.
  double resonance_tolerance = 1e-6;
  // Intervals shorter than this times max(|t|, 1) are decided by the signs at their ends.
  double min_relative_width = 64 * 2.220446049250313e-16;
  double divergence_bound = 1e12;   // |x|, |x'| beyond this is a DivergenceError
  long max_events = 100'000'000;    // per advance_to; beyond it a DivergenceError (Zeno motion)
  PreciseExponentialOptions exponential;  // for the augmented-exponential representation
  bool is_valid(std::string* why) const;
};

// Counters beyond IntegratorStats.
struct EventDrivenDiagnostics {
  long events = 0;             // spring switches (a simultaneous pair counts twice)
  long gap_samples = 0;        // closed-form evaluations of the gap functions
  long uncertified = 0;        // intervals too narrow for the bounds, decided by end signs
  long modal_modes = 0;        // distinct active sets represented modally
  long exponential_modes = 0;  // ... by the augmented exponential
  double worst_condition = 0;  // largest cond(V) among the modal modes
};

class EventDrivenSolver final : public Integrator {
 public:
  // Throws InputError for an invalid structure or options, or more than 62 springs.
  EventDrivenSolver(const GapStructure& structure, const EventDrivenOptions& options = {});
  ~EventDrivenSolver() override;
  EventDrivenSolver(const EventDrivenSolver&) = delete;
  EventDrivenSolver& operator=(const EventDrivenSolver&) = delete;

  std::string name() const override;
  Method method() const override { return Method::exact; }
  Index dofs() const override;
  void set_state(double t, const Vector& x, const Vector& v) override;
  double time() const override;
  const Vector& position() const override;
  const Vector& velocity() const override;
  void advance_to(double t_end, const StepObserver& observer = nullptr) override;
  // advance_to, and tangent (2n x p) <- J tangent with J the Jacobian of the flow from time() to
  // t_end (see above). Throws InputError when tangent does not have 2n rows.
  void advance_with_tangent(double t_end, Matrix& tangent,
                            const StepObserver& observer = nullptr) override;
  IntegratorStats stats() const override;

  EventDrivenDiagnostics diagnostics() const;
  // Whether spring j is touching now.
  bool touching(Index spring) const;
  // Called at every switch with its time, the spring and whether it starts touching.
  using EventObserver = std::function<void(double t, Index spring, bool touching)>;
  void set_event_observer(EventObserver observer);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The solver behind the Integrator interface.
std::unique_ptr<Integrator> make_event_driven_solver(const GapStructure& structure,
                                                     const EventDrivenOptions& options = {});

}  // namespace pwl
