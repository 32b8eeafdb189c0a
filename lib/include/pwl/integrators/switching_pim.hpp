#pragma once
// A higher-order precise integration method: the paper's step (one LCP per step with constant
// step operators, large steps, no stiffness update) without its two second-order errors.
//
// The plain PIM (He, Gao & Zhong 2018; Zhong & Williams 1994) integrates the linear part of
// the motion exactly and takes the spring forces P linear in time inside each step. That costs
// it two errors of order η²:
//  (a) where no spring switches, P(t) = K2 (W^T x(t) - Δ) on the touching springs is a smooth
//      curve, and the straight line through its ends misses it by O(η²) (the trapezoidal rule);
//  (b) where a spring switches inside a step, P has a kink there, which no polynomial in t
//      follows.
//
// This stepper removes both:
//  (a) Hermite-Taylor force polynomial. The force is interpolated by the polynomial of degree
//      d+1 that matches the first d time derivatives of P at the step start and the value
//      P_{k+1} at its end:
//
//          P(t_k + s) = Σ_{r=0}^{d} p_r (s/η)^r + (P_{k+1} - Σ_r p_r) (s/η)^{d+1},
//          p_r = P^{(r)}(t_k) η^r / r!.
//
//      The derivatives come from the state through the touching springs' own law,
//      P^{(r)} = K2_A W_A^T x^{(r)}, and x^{(r)} from the equation of motion
//      v^{(r+1)} = H v^{(r)} + G P^{(r)} + F^{(r)}(t): d products with H and the spring
//      directions, no new matrix. The step is then
//
//          v_{k+1} = T v_k + (harmonic responses) + Σ_r (Ξ̂_r - Φ) p_r + Φ P_{k+1},
//          Ξ̂_r = η^{-r} ∫_0^η e^{H(η-s)} s^r ds G,   Φ = Ξ̂_{d+1},
//
//      and P_{k+1} solves the same kind of LCP as the paper's, with the constant matrix
//      I - K2 W^T Φ_x. The moments Ξ̂_r ride along the 2^N doublings of T
//      (polynomial_force_integrals below). With d = 0 this is exactly the plain PIM step. The
//      local error is O(η^{d+3}) and the method has order d+2 where nothing switches.
//      End slope (end_derivative, on by default): the polynomial gets one more degree and also
//      matches the slope η P'(t_{k+1}) at the end. That slope is first predicted from the
//      start's Taylor data (one more term), enters the step and the LCP linearly, and is
//      corrected once from the new state, P' = K2_A W_A^T x'_{k+1}: two thin products more, one
//      order more (d+3), and a much smaller error constant. On figure 4a at η = T/200 the
//      default d = 2 puts the Poincaré points about 2e-10 from the exact solution (plain PIM:
//      6e-4).
//  (b) Located switches. Before the step, the Taylor polynomial of every gap function over the
//      step (known from the same derivatives) is screened for a sign change, and after it the
//      LCP's active set is compared with the one the step assumed. When either shows a switch,
//      the step is redone in pieces: the motion inside one mode is linear with polynomial and
//      harmonic forcing, so its Taylor series about the piece's start converges like
//      (||H_A|| h)^r / r! and is summed to rounding; the switching time is located on that
//      series by the safeguarded root search the exact solver uses (no grazing contact is
//      stepped over), the crossing springs change mode there, and the next piece starts. Only
//      the switching steps (a few per cent of them) pay for this.
//
// Tangent map (advance_with_tangent): the exact derivative of the numerical step map, applied to
// p tangent columns (2n x p, rows [x; x']); the motion is advance_to's to the last bit. With
// the modes and the LCP's active set those of the trajectory, a smooth step is affine in its
// start: its linear part is the same step with the loads and spring offsets left out and the LCP
// replaced by the solve on its active set A (dz_A = -M_AA⁻¹ dq_A, the LCP solution's derivative
// where A does not change). A switching step maps the tangent through each piece's homogeneous
// Taylor series at the piece's σ. There is no saltation term: a located switch's time depends on
// the start, but it enters only through the two modes' vector fields at the switch, which differ
// by the switching spring's force K2 (w^T x - Δ), zero at the root (the force is continuous).
// Central differences of the one-period map of figure 4a agree to about 3e-9, and the tangent
// converges to the exact flow's Jacobian at order 5. A tangent column costs about one state
// step; without a tangent nothing is added to a step.
//
// Costs: the smooth step is the plain step plus d products with H and the spring directions
// and d+2 thin products; a switching step costs some tens of smooth steps, and there is about
// one per spring switch. On figure 4a (η = T/200, five switches per period) the default costs
// about 2.5 times the plain PIM per step, construction included (pwl bench accuracy).
//
// The derivative terms and the series need η ||H_A|| to be moderate: a contact stiffness
// k2 >> k1 (α = k2/k1 large) makes the contact frequency ω_c = √((k1 + k2)/m) large, and for
// η ω_c beyond a few the Taylor data are useless. The constructor refuses (InputError naming
// `step`) when η ω_max exceeds max_step_argument; use force_degree = 0 with end_derivative =
// false (the paper's linear force, with located switches) or a smaller step there.
//
// The banded stepper. The design carries over: the smooth step is products with constant
// operators (T, Ξ̂_r G: banded for a chain, SPEC §4) and with H, W, K2 (sparse), plus the one
// constant LCP matrix I - K2 W^T Φ_x (banded too). This implementation is dense (the fixed-size
// path for up to 6 springs, dynamic sizes otherwise); the banded one is
// make_banded_switching_pim (banded_switching_pim.hpp): (1) the moments Ξ̂_r [0; I],
// r = 0..d+2, of every substructure (polynomial_force_integrals on the substructure's H, next to
// the rising and falling loads, which are Ξ̂_1 and Ξ̂_0 - Ξ̂_1) in a banded assembly, and (2)
// sparse products in the Taylor recursion and the pieces (O(n) per term instead of O(n²)). Not
// done yet: to stay cheap on long chains where a spring switches in nearly every step, (3)
// pieces restricted to the band around the switching spring.
//
// References: W. X. Zhong and F. W. Williams, Proc. IMechE C 208 (1994) 427-430 (precise
// integration); C. F. Van Loan, IEEE TAC 23 (1978) 395-404 (integrals of the exponential);
// M. Hochbruck and A. Ostermann, "Exponential integrators", Acta Numerica 19 (2010) 209-286
// (exponential quadrature with polynomial forcing); L. F. Shampine and S. Thompson, Comput.
// Math. Appl. 39 (2000) 43-54 (event location); E. Hairer, S. P. Nørsett and G. Wanner, Solving
// ODEs I, §II.6 (steps that straddle a discontinuity lose the order of the method).
#include <memory>
#include <string>
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/numerics/lcp_solver.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

// T = exp(Hη) and the scaled moments Ξ̂_r = η^{-r} ∫_0^η e^{H(η-s)} s^r ds G, r = 0..degree,
// by the 2^N algorithm: at τ0 = η/2^N, Ξ̂_r(τ0) = Σ_k H^k G τ0^{k+1} r!/(k+r+1)!, and each
// doubling Ξ̂_r(2τ) = 2^{-r} [T(τ) Ξ̂_r(τ) + Σ_{i<=r} C(r,i) Ξ̂_i(τ)] (split the integral at τ
// and expand (u + τ)^r). Ξ̂_0 = Γ0 G and Ξ̂_1 = Γ0 G - Γ1 G/η in the notation of
// precise_exponential.hpp. Throws InputError for bad sizes, η <= 0 or degree outside 0..12.
struct PolynomialForceIntegrals {
  Matrix transition;            // T
  std::vector<Matrix> moments;  // Ξ̂_0 .. Ξ̂_degree
};
PolynomialForceIntegrals polynomial_force_integrals(const Matrix& H, double eta, const Matrix& G,
                                                    int degree,
                                                    const PreciseExponentialOptions& options = {});

struct SwitchingPimOptions {
  double step = 0.0;          // η > 0
  int force_degree = 2;       // d in 0..8: derivatives of P used; order d + 2 (d + 3 with end_derivative)
  bool locate_switches = true;
  // Also match the slope of P at the step end, predicted from the start's Taylor data and
  // corrected once from the new state: one more order (d + 3) for two thin products.
  bool end_derivative = true;
  LcpAlgorithm lcp_solver = LcpAlgorithm::block_pivoting;
  PreciseExponentialOptions exponential;
  double divergence_bound = 1e12;
  // Largest η ω_max allowed (ω_max: the largest |eigenvalue| of H with every spring touching,
  // as contact_frequency in step_guard.hpp bounds it; the method table's step guard refuses
  // beyond the same 2).
  double max_step_argument = 2.0;
  // Pieces of a switching step whose series needs more terms than this are halved.
  int max_series_terms = 40;
  bool is_valid(std::string* why) const;
};

struct SwitchingPimDiagnostics {
  long steps = 0;
  long switching_steps = 0;  // steps redone in pieces
  long local_steps = 0;      // of those, corrected locally (banded stepper)
  long local_rows = 0;       // rows of their corrections' series, summed over their pieces
  long free_windowed = 0;    // of the local ones, with the motion without the switches from
                             // T y and its gaps from windows (banded stepper, no spring touching)
  long halved_pieces = 0;    // pieces of switching steps halved for their series to converge
  long pieces = 0;           // pieces of those steps
  long switches = 0;         // located spring switches
  long screened = 0;         // steps the gap screen could not clear (a possible switch)
  long cleared = 0;          // of those, kept smooth by the windowed gap series (banded stepper)
  long lcp_mismatches = 0;   // switching steps found by the LCP rather than the screen
  long gap_samples = 0;      // evaluations of the gap polynomials by the root search
  double step_argument = 0;  // η ω_max
  bool from_period = false;  // operators laid out from a short chain (banded stepper)
};

class SwitchingPim : public Integrator {
 public:
  virtual SwitchingPimDiagnostics diagnostics() const = 0;
};

// Throws InputError for an invalid structure or options (naming the field).
std::unique_ptr<SwitchingPim> make_switching_pim(const GapStructure& structure,
                                                 const SwitchingPimOptions& options);

}  // namespace pwl
