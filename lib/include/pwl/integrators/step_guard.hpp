#pragma once
// The step guard: whether a fixed step can resolve a structure's stiffest contact, judged by the
// method table.
//
// A fixed-step method (the PIM and its switching form) integrates the linear part of the motion
// exactly at any step, so nothing in the step itself fails when a contact is far too stiff for
// it: the paper's PIM at η = T/20 on figure 4a's chain with α = k2/k1 = 1e9 runs to the end and
// returns |x| ≈ 650 where the motion stays below 2. What decides is η ω_max, the step against the
// highest frequency the structure reaches with every gap spring touching: a contact lasts about
// half of its period π/ω, and a step that long cannot see it. Each fixed-grid row of the method
// table carries two limits on η ω_max, measured with `pwl bench stability` (the numbers are in
// method_table.cpp): beyond `step_warning` the contact is under-resolved and the error grows
// quickly; beyond `step_limit` the method misses contacts or blows up. check_step() judges a
// step against them and says which step would do; the program decides what to do with a
// warning or a refusal (pwl refuses with exit code 2 unless --force).
//
// Rows without a step guard: the adaptive Runge-Kutta methods choose their own steps, and their
// error control rejects a step that straddles a contact it cannot follow (kink-located, they end a
// step at every switch), so no step of theirs is fixed in advance to judge; what decides their
// accuracy is the tolerance. pwl bench stability finds them missing contacts or settling on the
// wrong regime at tolerances 1e-3 and 1e-4 and never at 1e-5 or tighter, so check_step() warns
// (never refuses) for a tolerance looser than 1e-5 and returns ok otherwise. The exact
// event-driven solver has no step: it follows every mode in closed form, and its work is bounded
// by its own budget (event_driven_solver.hpp). check_step() returns ok for it.
#include <string>

#include "pwl/integrators/method_table.hpp"
#include "pwl/model/gap_structure.hpp"

namespace pwl {

// The highest frequency of the structure with every gap spring touching, as an upper bound of the
// largest |λ| of its state matrix H = [[0, I], [-M⁻¹K_all, -M⁻¹C]] (K_all = K + W K2 W^T).
//
// For an eigenpair (λ, φ) of (λ² M + λ C + K_all) φ = 0, the Rayleigh quotients m = φ*Mφ,
// c = φ*Cφ, k = φ*K_all φ (M, C, K_all symmetric, M positive definite) give λ² m + λ c + k = 0:
// either a complex pair with |λ|² = k/m <= λ_max(K_all, M), or real roots with |λ| <= c/m <=
// λ_max(C, M). So |λ| <= ω_max = max(√λ_max(K_all, M), λ_max(C, M)): the undamped natural
// frequency, unless a damping rate is faster. Both generalized eigenvalues are computed exactly
// (dense symmetric-definite solver) up to kDenseFrequencyDofs degrees of freedom. Beyond, each is
// bounded by Gershgorin's theorem: on M^{-1/2} A M^{-1/2} when M is diagonal, λ_max(A) over a
// lower bound of λ_min(M) otherwise. We chose an upper bound over a few power iterations, which
// approach λ_max from below and so would pass a step slightly too long; the bound is tight where
// it matters, since a stiff contact dominates its row (on a chain, α + 4 against α + 3.68).
struct ContactFrequency {
  double omega_max = 0.0;     // max(undamped, damping_rate)
  double undamped = 0.0;      // √λ_max(K_all, M)
  double damping_rate = 0.0;  // λ_max(C, M)
  bool bound = false;         // Gershgorin bounds (large structures), not the eigenvalues
};
constexpr long kDenseFrequencyDofs = 400;
// Throws InputError for an invalid structure, or a non-diagonal mass matrix beyond
// kDenseFrequencyDofs that Gershgorin cannot bound away from singular.
ContactFrequency contact_frequency(const GapStructure& structure);

enum class StepVerdict { ok, warning, refusal };

// What the guard says about one fixed step.
struct StepCheck {
  StepVerdict verdict = StepVerdict::ok;
  double step = 0.0;
  double omega_max = 0.0;      // contact_frequency(structure).omega_max
  double step_argument = 0.0;  // η ω_max (0 for a row without a step guard)
  double warning_limit = 0.0;  // the row's limits on η ω_max (0: no step guard)
  double refusal_limit = 0.0;
  // The largest step with no warning (warning_limit / ω_max) and with no refusal
  // (refusal_limit / ω_max); infinite for a row without a step guard or when ω_max = 0.
  double largest_step = 0.0;
  double largest_accepted_step = 0.0;
  // With a forcing period T: the fewest steps per period T/N with no warning (0: no period
  // given, or no guard).
  long steps_per_period = 0;
  // Empty when ok; otherwise one paragraph for people: the method, the step, η ω_max and
  // ω_max, the limit it passes and why, and the step to use.
  std::string message;
  bool ok() const { return verdict == StepVerdict::ok; }
  bool refused() const { return verdict == StepVerdict::refusal; }
};

// Judges settings.step for settings.method on `structure`. For a row without a step guard
// (method_traits(m).step_limit == 0) returns ok with ω_max still estimated, or, for an adaptive
// row with a tolerance looser than 1e-5, a warning about the tolerance (step_argument 0). When `period` > 0
// (the loads' common period, on whose grid the step must land), the message and
// steps_per_period name the whole number of steps per period to use. Throws InputError for
// settings that are not valid for the structure (MethodSettings::is_valid).
StepCheck check_step(const GapStructure& structure, const MethodSettings& settings,
                     double period = 0.0);

}  // namespace pwl
