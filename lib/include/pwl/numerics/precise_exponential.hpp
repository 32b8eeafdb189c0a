#pragma once
// The precise integration method's matrix exponential and load integrals (Zhong & Williams,
// "A precise time step integration method", Proc. IMechE C 208 (1994) 427-430; Zhong, "On precise
// integration method", J. Comput. Appl. Math. 163 (2004) 59-78).
//
// T = exp(Hη) by the 2^N algorithm: start from τ = η/2^N, where a 4th-order Taylor series is exact
// to rounding, and double N times. Only the increment T_a = T - I is stored and doubled,
// T_a <- 2 T_a + T_a T_a, so the small increment is never swamped by the identity.
//
// The load integrals ride along the same doublings with no matrix inverse (SPEC.md §3; Van Loan,
// "Computing integrals involving the matrix exponential", IEEE TAC 23 (1978) 395-404, gives the
// block-triangular view these recurrences come from):
//
//     Γ0(τ) = ∫_0^τ e^{Hu} du           Γ0(2τ) = Γ0 + T(τ) Γ0
//     Γ1(τ) = ∫_0^τ e^{Hu} u du         Γ1(2τ) = Γ1 + T(τ)(Γ1 + τ Γ0)
//     Kω(τ) = ∫_0^τ e^{H(τ-s)} e^{iωs} ds   Kω(2τ) = T(τ) Kω + e^{iωτ} Kω
//
// Because none of them inverts H or (ω²I + H²), a singular stiffness (a free-free structure) and
// undamped resonance need no special case. Each is only needed applied to a few columns
// (the spring directions, the load vectors), so they are carried as thin matrices and every
// doubling costs one product of T_a with a (2n x p) block beside the T_a T_a product.
#include "pwl/types.hpp"

namespace pwl {

struct PreciseExponentialOptions {
  int doublings = 20;    // N at most: the Taylor series starts at τ = η / 2^N
  int taylor_order = 4;  // terms of the series at τ (the paper's 4 is exact to rounding for N = 20)
  // Run fewer doublings where a larger τ is already exact to rounding (doublings_used below):
  // N = 20 is what the paper takes for any H, and for a moderate ‖Hη‖ half of those doublings
  // only shrink a remainder that is already below the unit roundoff. Off by default, so that the
  // dense PIM's motion is the paper's N = 20 to the bit (a chaotic motion, and every figure made
  // from one, changes with the last bit of T). The banded exponential turns it on for its
  // substructures (banded_exponential.hpp), whose construction is the cost being cut.
  bool trim_doublings = false;
  bool is_valid(std::string* why) const;
};

// The doublings the 2^N algorithm runs for H, η and load frequencies up to `frequency`: with
// trim_doublings, the fewest N <= options.doublings at which θ = (‖H‖ + frequency) η / 2^N
// (‖H‖ the larger of the 1- and ∞-norms) makes the series' remainder relative to the increment,
// θ^p / (p+1)! for order p, no larger than the unit roundoff 2^-53 (p = 4: θ <= 3.4e-4, so
// ‖Hη‖ = 1 takes N = 12; p = 8: θ <= 0.050, N = 5), and θ <= 1/2. The load integrals' series
// converge at least as fast (their k-th terms carry 1/(k+1)! or less, and the harmonic ones
// (‖H‖ + |ω|)^k). A series whose θ is that small is exact to rounding, as the paper's N = 20 of
// order 4 is for ‖Hη‖ up to about 350; beyond the cap N stays at options.doublings, as before.
// Without trim_doublings: options.doublings.
int doublings_used(const Matrix& H, double eta, double frequency,
                   const PreciseExponentialOptions& options);

struct PreciseExponential {
  Matrix transition;        // T = exp(Hη)
  Matrix gamma0;            // Γ0(η) G
  Matrix gamma1;            // Γ1(η) G
  Matrix harmonic_real;     // Re Kω_j(η) b_j, one column per (ω_j, b_j) pair
  Matrix harmonic_imag;     // Im Kω_j(η) b_j
};

// T = exp(Hη), Γ0 G, Γ1 G and Kω_j(η) b_j for every column b_j of B with its frequency omegas[j].
// G and B may have zero columns. Throws InputError for a non-square H, non-finite input, η <= 0,
// or mismatched sizes.
PreciseExponential precise_exponential(const Matrix& H, double eta, const Matrix& G,
                                       const Matrix& B, const Vector& omegas,
                                       const PreciseExponentialOptions& options = {});

// Just T = exp(Hη).
Matrix precise_exponential(const Matrix& H, double eta,
                           const PreciseExponentialOptions& options = {});

}  // namespace pwl
