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
//     are cached by active set. The eigenvectors are those of the balanced matrix D H_A D⁻¹, D
//     scaling each displacement by its degree of freedom's own frequency (a power of two near
//     √((M⁻¹K_A)_ii), after Parlett and Reinsch's balancing, Numer. Math. 13 (1969) 293-304):
//     unbalanced, a contact of frequency ω pairs displacements of size 1/ω with velocities of
//     size 1, cond(V) grows like ω, and the modal form loses cond(V)·eps of the state in every
//     gap. On figure 4a's chain the contact states reach cond(V) = 7e4 at α = k2/k1 = 3e8 and
//     pass 1e5 at 1e9 (13 balanced, for any α); at 1e9 the unbalanced modal form puts gap errors
//     of 1e-13 on a contact penetration of 1e-11 (measured against a long-double exponential):
//     enough for a spring to chatter on its kink without end. The homogeneous
//     coefficients start from the real state less the real particular response, so they are
//     conjugate-symmetric like the modes and carry no imaginary part into the derivative bounds.
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
//     come from the logarithmic norm of Ĥ_A, balanced like the modal form (in balanced
//     coordinates a stiff contact is a rotation at its own frequency, so the sample spacing is
//     about 1/ω of the current mode, not 1/ω²). We chose the eigen-decomposition as the first
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
//     a start from rest exactly at the kinks, where g = g' = g'' = 0. The gaps and rates at the
//     start of a mode are taken from the state itself, not from the mode's reconstruction of it.
//     Near a lift-off (a contact force through zero) a rate can be significant against the
//     small scale of the touching mode and below the threshold in the slack one; each mode
//     would then send the spring to the other at the same instant. The lower-order derivative
//     decides: at the kink the first derivatives of a gap are the same in both modes.
//  4. Work. Between events the gaps are sampled as far apart as their derivative bounds allow,
//     and at least the current mode's own spacing (π/4 over its largest |λ|): a free-flight
//     mode is never sampled at a contact's frequency, and a stiff contact that stays closed
//     is sampled only as finely as its own vibration makes necessary. On figure 4a's chain over
//     200 periods from rest every α from 2 to 1e10 takes about 10 gap evaluations per switch
//     (tests/integrators/event_driven_stiff_test.cpp bounds it). The augmented-exponential
//     representation bounds derivatives by norms, not by the motion's own modal sizes, so in a
//     stiff contact it samples at about the contact's period for as long as the contact lasts
//     (1e6 evaluations for a period at α = 1e9, 0.3 s): bounded, but not by the events. The
//     modal form gives way to it when a load comes within resonance_tolerance times the
//     mode's spectral scale of a mode; a stiff contact makes that scale its own frequency, so
//     on figure 4a's chain the soft modes of some contact states count as resonant from
//     α ≈ 3e10 (|iω - λ| = 0.1 against 1e-6 · 1.7e5), and at α = 1e11 one period spends the
//     default gap-sample budget in about 5 s.
//  5. Budget and progress. One advance_to call stops with BudgetError once it has located more
//     than max_events crossings or spent max_gap_samples gap evaluations (a contact too stiff or a
//     chattering grazing point would otherwise run for hours); the solver is left at the time
//     it reached, in a consistent state. A program can watch a long call through `progress`.
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

// What a long advance_to call has done so far (EventDrivenOptions::progress).
struct EventDrivenProgress {
  double t = 0.0;         // time reached: the motion is known up to here
  double t_start = 0.0;   // the call's interval
  double t_end = 0.0;
  long events = 0;        // switches located in this call
  long gap_samples = 0;   // gap evaluations in this call
  double seconds = 0.0;   // wall time since the call began
};

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
  // The work budget of one advance_to (or advance_with_tangent) call: beyond it, BudgetError.
  // Crossings located (each switch found, a touch settled back at once included) and gap
  // evaluations. Measured over 200 periods of figure 4a's chain from rest: 5 to 7 switches and
  // 45 to 65 evaluations per forcing period, about 10 per switch, for every α from 2 to 1e10
  // (gap 0.1 and α = 1e9 alike); a 20-mass chain about 80 per period. pwl advances a period or
  // a few per call, so every use in the repository stays below 1/1000 of both. Spent, they stop
  // a pathological call within seconds (an evaluation costs about 1 µs on 5 masses, a few on
  // 20) instead of running for hours. Raise them for one very long call, or split it.
  long max_events = 1'000'000;
  long max_gap_samples = 10'000'000;
  // Progress of a long call: called from inside advance_to, at the first switch or every 1024
  // gap evaluations once progress_interval seconds of wall time have passed since the call
  // began or since the last call of the hook; never when the call ends sooner. For a program's
  // report on stderr: pwl prints nothing itself. What the hook throws abandons the call (the
  // solver stays at the last switch it completed). It runs on the thread that calls advance_to:
  // settings copied to the threads of a sweep share it, and it must synchronize what it shares.
  std::function<void(const EventDrivenProgress&)> progress;
  double progress_interval = 1.0;
  PreciseExponentialOptions exponential;  // for the augmented-exponential representation
  bool is_valid(std::string* why) const;
};

// Counters beyond IntegratorStats.
struct EventDrivenDiagnostics {
  long events = 0;             // spring switches (a simultaneous pair counts twice)
  long crossings = 0;          // crossings located: the switches and the touches settled back
  long gap_samples = 0;        // closed-form evaluations of the gap functions
  long uncertified = 0;        // intervals too narrow for the bounds, decided by end signs
  long modal_modes = 0;        // distinct active sets represented modally
  long exponential_modes = 0;  // ... by the augmented exponential
  double worst_condition = 0;  // largest cond(V) among the modal modes
};

class EventDrivenSolver final : public Integrator {
 public:
  // Throws InputError for an invalid structure or options, or more than 62 springs. advance_to
  // and advance_with_tangent throw BudgetError when the call's budget is spent (see the
  // options), DivergenceError when the state leaves divergence_bound.
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
