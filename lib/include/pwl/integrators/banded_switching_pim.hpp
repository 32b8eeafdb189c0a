#pragma once
// The higher-order precise integration method of switching_pim.hpp with banded operators: the
// same step (Hermite-Taylor force polynomial, one constant LCP per step, switches located on the
// Taylor series of the motion), for chain-like structures, with work and memory per smooth step
// O(n q) instead of O(n²).
//
// What is banded, and why it may be. A smooth step of the switching PIM is
//
//     v_{k+1} = T v_k + (harmonic responses) + Σ_r C_r p_r + Φ P_{k+1} + S (η P'_{k+1} - guess),
//
// with constant operators T = exp(Hη) and C_r, Φ, S, fixed combinations of the scaled moments
// Ξ̂_r = η^{-r} ∫_0^η e^{H(η-s)} s^r ds G, r = 0..d+2, with G = [0; -M⁻¹W]. For a periodic chain the
// entries of T fall off faster than exponentially with the distance between degrees of freedom
// (He, Gao & Zhong 2018, §2; SPEC.md §4), and so do those of every moment: Ξ̂_r [0; I] is a
// weighted integral of e^{H(η-s)} [0; I] over the step, and the weight s^r only moves it towards
// the short times, which reach less far. So the moments are read off the same small
// substructures as T and the linear-load integrals (banded_exponential.hpp, whose rising and
// falling loads are Ξ̂_1 and Ξ̂_0 - Ξ̂_1): polynomial_force_integrals on each substructure's H
// with G = [0; I], the step's combinations taken there, and the rows assembled into banded
// matrices with the band q the banded exponential chose for T. Products with the sparse spring
// directions (multiply(BandedMatrix, SparseMatrix)) give the 2n x m operators; the LCP matrix
// I - K2 W^T Φ_x is banded and goes to the banded block-pivoting solver, warm-started from the
// previous step's active set (banded_lcp_solver.hpp).
//
// The rest of the step uses H, W and K2 as narrow banded matrices (their non-zeros; a uniform
// chain's rows stored once and applied as stencils): the Taylor recursion that gives the force
// derivatives p_r (v^{(r+1)} = H v^{(r)} + G P^{(r)} + F^{(r)}) costs O(nnz(H)) = O(n) per term,
// and the C_r p_r are added from the columns of the touching springs only. The searches for
// switches look only at the springs whose gaps can reach their kinks in the piece. A smooth step
// therefore costs one banded product T v and d + 1 sparse recursion terms, plus O(contacts · q).
//
// Switching steps are redone exactly on the Taylor series of the motion, as in the dense stepper,
// but corrected locally: the series of the start mode over the whole step on the whole state
// (O(n) per term, sparse H), and from the first switch on the series of the correction the
// switches make, on the rows it reaches (O(window) per term); switches are located on the gap
// polynomials by the safeguarded root search of event_location.hpp
// (local_switch_correction.hpp). Where that is enough (windowed_free_motion), the motion the
// correction is added to is the free one, every spring open, whose end is T y (exact: no spring
// force to approximate) and whose gaps come from its series on windows of rows around the
// springs that may switch and those touching, which are then sources of the correction from the
// step's start: one product T y and O(window) per term instead of the whole state's series. Where springs switch all along the chain at once the stepper
// redoes the step on the whole state instead, as the dense stepper does (switch_correction).
// Before that, a step whose gap screen (the gap polynomials of degree d + 1) cannot clear every
// spring is screened again on the gap polynomials to rounding of the springs it left, from the
// Taylor series on windows of rows around them (local_gap_screen.hpp): when they show no switch
// and no spring on its kink, the step stays smooth (the springs the first screen cleared are
// trusted, as in every smooth step). On the paper's 1000-mass chain that keeps 205 of 400 such
// steps smooth at η = 0.4 s, 82 of 250 at 0.8 s.
//
// The numbers are those of the dense make_switching_pim up to the band's truncation (the
// tolerance of BandedExponentialOptions, 1e-15 of each operator block by default) and rounding,
// but for the steps the second screen keeps smooth, which the dense stepper redoes on the series:
// there the two differ by the smooth step's own error (none while no spring touches), and by a
// switch of a spring the first screen cleared, which the dense stepper's full search would see.
// Where the windows would cover a quarter of the rows (a window is about 2 K + 1 masses, K the
// series' length, up to max_series_terms) the step goes to the switching path as before.
//
// Tangent map (advance_with_tangent): the dense stepper's (switching_pim.hpp), the derivative of
// the numerical step map applied to p columns (2n x p, rows [x; x'], not interleaved), column by
// column with the step's own banded and sparse products: a smooth step costs one product with T,
// d + 1 recursion terms and the touching springs' forces per column (the terms only on the rows
// within at most d reaches of the springs touching at the step's start, none when none touch, the
// whole state when those rows are half the chain or more), the LCP's active-set solve a band LU
// of M_AA (refactorised only from the first index where the active set changed), and a piece of
// a switching step its Taylor terms; O(n q) per column and step, nothing 2n x 2n.
//
// Tangent replay (Integrator::record_tangent, replay_tangent): while recording, the stepper notes,
// in advance_to as in advance_with_tangent, what fixes its tangent map (each step's start, its
// smooth steps, the pieces of its switching steps with their lengths and series terms, the
// springs' mode changes) and applies that record again to other columns without the state's
// series, the search for switches or the LCP. The columns come out as advance_with_tangent gives
// them, to the last bit. On the 1000-mass chain of `pwl bench orbits`, whose springs switch about
// 2000 times a period, a replayed product costs about a third of an integration with its tangent.
//
// References: W. X. Zhong and F. W. Williams, Proc. IMechE C 208 (1994) 427-430 (precise
// integration); He Dongdong, Gao Qiang and Zhong Wanxie, Appl. Math. Mech. 39(7) (2018) 737-749
// (the banded exponential of periodic structures); C. F. Van Loan, IEEE TAC 23 (1978) 395-404
// (integrals of the exponential); M. Hochbruck and A. Ostermann, "Exponential integrators",
// Acta Numerica 19 (2010) 209-286 (exponential quadrature with polynomial forcing); L. F.
// Shampine and S. Thompson, Comput. Math. Appl. 39 (2000) 43-54 (event location); E. Hairer,
// S. P. Nørsett and G. Wanner, Solving ODEs I, §II.6 (steps that straddle a discontinuity lose
// the order of the method).
#include <memory>
#include <string>

#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/numerics/banded_lcp_solver.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/switching_pim.hpp"

namespace pwl {

struct BandedSwitchingPimOptions {
  // Step, force degree, end slope, switch location, series limits, divergence bound and the
  // largest step argument, as for the dense stepper. Its lcp_solver is not used: the banded
  // stepper always solves its LCP with BandedLcpSolver (`lcp` below).
  SwitchingPimOptions pim;
  BandedExponentialOptions band;  // tolerance (or a forced band q), substructures, N
  BandedLcpOptions lcp;
  // How switching steps are corrected (local_switch_correction.hpp). `local`: the series of the
  // correction the switches make, on the rows it reaches; `whole_state`: every piece redone on
  // the whole state, as the dense stepper does; `automatic`: local while the correction stays
  // within a quarter of the rows, otherwise the step is redone on the whole state (springs
  // switching all along the chain at once), and the next few switching steps go there directly.
  // The three agree to rounding.
  enum class SwitchCorrection { automatic, local, whole_state };
  SwitchCorrection switch_correction = SwitchCorrection::automatic;
  // A locally corrected step takes the motion its correction is added to as the free motion
  // (every spring open; the springs touching at the start become sources of the correction):
  // its end from T y (exact: no spring force to approximate) and its gap polynomials from its
  // series on windows of rows around the springs the gap screen left and the touching ones,
  // instead of the start mode's series on the whole state. Where the windows cannot decide the
  // step it goes to the whole state's series (local_switch_correction.hpp). false: always the
  // whole state's series. The two agree to rounding, not to the bit; advance_with_tangent and a
  // recording advance_to always take the whole state's series, so with this on they agree with a
  // plain advance_to to rounding.
  bool windowed_free_motion = true;
  // Ceres-style check: false with a message naming the field (pim.step, band.tolerance, ...)
  // and its value.
  bool is_valid(std::string* why) const;
};

// The banded higher-order PIM. Throws InputError for invalid options or structure (naming the
// field), a mass matrix that is not diagonal, a step too large for the contact stiffness (as the
// dense stepper) or no band within the tolerance.
std::unique_ptr<SwitchingPim> make_banded_switching_pim(const GapStructure& structure,
                                                        const BandedSwitchingPimOptions& options);

}  // namespace pwl
