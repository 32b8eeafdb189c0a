#pragma once
// Floquet multipliers: the eigenvalues of the monodromy matrix M = ∂φ_{kT}/∂y of a period-k orbit.
// An orbit is asymptotically stable when every multiplier lies inside the unit circle, and it
// loses stability where one leaves it: through +1 (a fold, or a branch point), through −1 (period
// doubling), or as a complex pair (Neimark–Sacker, a torus is born). A forced system has no
// trivial multiplier at 1 (there is no phase to shift), so all 2n count.
//
// For a small structure the monodromy is formed and all multipliers are its eigenvalues. For a
// long chain only products M v are affordable (one integration of k periods with a tangent vector
// each), and the leading few multipliers, those of largest modulus that decide stability, come
// from Arnoldi's method on those products (Y. Saad, Numerical Methods for Large Eigenvalue
// Problems, 2nd ed., SIAM 2011, ch. 6; the use for periodic orbits after K. Lust, D. Roose,
// A. Spence and A. R. Champneys, SIAM J. Sci. Comput. 19 (1998) 1188-1209), restarted thick: each
// restart keeps the span of more Ritz vectors than wanted (G. W. Stewart, SIAM J. Matrix Anal.
// Appl. 23 (2001) 601-614; R. B. Morgan, Math. Comp. 65 (1996) 1213-1230).
//
// Why the basis is large by default. A long chain damped in proportion to its stiffness has its
// long-wave modes as the leading multipliers, crowded against μ = 1: on the 1000-mass chain of
// `pwl bench orbits`, |μ_k| ≈ 1 − 4e-6 k² at angles ≈ 0.0131 k. Arnoldi separates them only with
// a basis that resolves that crowd: there, 60 vectors with explicit restarts did not converge in
// 660 products (residual 7.6e-2), 100 thick-restarted vectors not in 1050, 150 converged in 800
// products and 200 in 590 (residual 1e-15; the leading pair 0.999996 e^{±0.0131i}). The basis
// takes 8 · size · (krylov_dimension + 1) bytes: 3.2 MB for 1000 masses, 320 MB for 10^5.
// At 3000 masses and beyond the crowd outgrows any affordable basis and Arnoldi does not converge.
//
// Where the structure's linear part gives an approximate shifted inverse (the open structure's
// (M0 − σI)⁻¹ under classical damping: pwl's Newton–Krylov preconditioner), a preconditioned
// Davidson iteration (preconditioned_floquet_multipliers, below) separates the crowd by where each
// multiplier lies in the plane instead of by modulus: on the paper's chain at θ = 1.5 the leading
// six in 127 products at 1000 masses (Arnoldi: 690) and converged at 3000 and 10^4 masses, where
// Arnoldi does not. Matrix-free shooting and continuation take it wherever it is available
// (ArnoldiOptions::method).
#include <complex>
#include <functional>
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::orbits {

struct FloquetMultipliers {
  // Largest modulus first; complex pairs adjacent, the one with positive imaginary part first.
  std::vector<std::complex<double>> values;
  // All 2n multipliers (from the dense monodromy), or only the leading ones (Arnoldi).
  bool complete = true;
  // Arnoldi: the largest residual estimate of the reported values (0 for the dense ones), and
  // whether it met the tolerance. A lightly damped long chain has many multipliers on a ring just
  // inside the unit circle, where Arnoldi converges slowly; when it has not converged, the
  // stability verdict is not to be trusted (callers say "undetermined").
  double residual = 0.0;
  bool converged = true;
  // Whether every multiplier of modulus above 1 − ArnoldiOptions::margin is among the values
  // (always for the dense ones; for Arnoldi, when it converged with its smallest value below
  // that, or reported all of them).
  bool band_covered = true;
  // How they were found: the dense monodromy's eigenvalues, thick-restarted Arnoldi, or Davidson
  // preconditioned by the open structure (preconditioned_floquet_multipliers).
  enum class Method { dense, arnoldi, davidson };
  Method method = Method::dense;

  double largest_modulus() const;
  // Asymptotically stable: every multiplier strictly inside the unit circle by more than
  // `margin`. (With the leading ones only, this is decided by the largest of them, which
  // Arnoldi finds first.)
  bool stable(double margin = 0.0) const;
  // Multipliers outside the unit circle.
  int unstable_count() const;
  // Re Π (1 − μ_i / target) over the reported multipliers, target = ±1: det(I − M) or det(I + M)
  // when they are all of them, the test function of a fold or a period doubling. With the leading
  // ones only (Arnoldi) the product leaves out multipliers inside the unit circle, each of whose
  // factors is positive (a real μ inside gives 1 ∓ μ > 0, a complex pair |1 ∓ μ|² > 0), so a
  // multiplier that enters or leaves the leading set between two points does not change the sign:
  // the sign changes where, and only where, a real multiplier crosses ±1.
  double shifted_determinant(double target) const;
};

// All eigenvalues of a dense monodromy, sorted. Throws InputError for a non-square or non-finite
// matrix.
FloquetMultipliers floquet_multipliers(const Matrix& monodromy);

struct ArnoldiOptions {
  int count = 6;            // leading multipliers wanted
  int krylov_dimension = 200;  // basis size (> count; at most the operator's size is used)
  int max_restarts = 10;
  double tolerance = 1e-10;  // residual of a Ritz pair relative to max(|μ_1|, 1)
  unsigned seed = 1;         // the starting vector (fixed: the answer is reproducible)
  // Columns per call of the operator (block Krylov-Schur): the basis grows by `block` products
  // at a time, which a caller can spread over threads (StroboscopicMap does). 1: plain Arnoldi.
  // At most krylov_dimension − count are used.
  int block = 1;
  // The band of moduli that must be covered: every multiplier with |μ| > 1 − margin is reported.
  // While the smallest value reported lies in the band (and Arnoldi converged), the count doubles,
  // up to half the basis, and the same Krylov-Schur decomposition goes on from its thick restart;
  // FloquetMultipliers::band_covered says whether it got below. 0: every multiplier outside the
  // unit circle. Continuation's band round the circle (ContinuationOptions::band), narrowed to
  // what the reported multipliers cover, is not narrowed below this margin where they converged;
  // continuation asks 1e-5 by default (continuation_shooting_options, continuation.hpp).
  // On the 1000-mass orbit of `pwl bench orbits` (|μ_k| ≈ 1 − 4e-6 k², a crowd of ~480 round the
  // circle; blocks of two, 200 vectors) margins of 0, 1e-4, 1e-3 and 4e-3 took 690, 784, 1036
  // and 1088 products for 6, 12, 48 and 96 multipliers (asked for directly, 32 or 64 take 704 and
  // 676: the crowd, not the count, sets the cost; the doublings add the restarts).
  double margin = 0.0;
  // Where an approximate shifted inverse of the operator is at hand (the open structure's
  // (M0 − σI)⁻¹ under classical damping), the leading multipliers can come from a preconditioned
  // Davidson iteration instead (preconditioned_floquet_multipliers): `automatic` takes it there
  // and Arnoldi elsewhere; `arnoldi` always Arnoldi. Davidson uses the same count, basis size
  // (krylov_dimension), restarts, tolerance, seed, margin and warm start.
  enum class Method { automatic, arnoldi };
  Method method = Method::automatic;
  // Davidson's basis, larger than Arnoldi's: a crowd has to be resolved before the first restart,
  // which keeps only what the leading Ritz vectors hold. On the paper's chain at θ = 1.5
  // (2026-12-01) its leading three pairs converged, unrestarted, at 127 columns for 1000 masses,
  // 237 for 3000 and 485 for 10^4; with 200, restarted, 3000 masses had not converged after 800
  // products. Fewer are used where V and M V (16 · size bytes a column) would exceed 1 GiB.
  int davidson_dimension = 600;
  bool is_valid(std::string* why) const;
};

// The `count` multipliers of largest modulus of the operator `apply` (which replaces the columns of
// its argument, size x p, by M times them) by thick-restarted Arnoldi. `complete` is false unless count
// reaches `size`. A complex pair is reported whole: the count grows by one where it would cut a
// pair in two, and doubles while the smallest reported lies in the band of ArnoldiOptions::margin.
// Where the basis spans the whole space (size <= the Krylov dimension) every multiplier of the
// band is reported at once, since each is then exact. Throws InputError for invalid options.
//
// Warm start (continuation, where the orbit moves little from one point to the next): `warm`, the
// Ritz vectors of a nearby operator (size x k, complex, as `vectors` returns them), gives the real
// Schur vectors of its leading multipliers (an orthonormal basis of their invariant subspace, in
// their order), and the iteration starts from their sum plus a tenth of the fixed random vector,
// so that the leading subspace is found again in few products while a multiplier that was not
// among them (one that grows past them) still has a component to grow from. `vectors`
// (optional) receives the Ritz vectors of the reported multipliers, column i for values[i], each
// of unit 2-norm: the eigenvector of a multiplier that crosses −1, for branch switching, and the
// next warm start.
FloquetMultipliers leading_floquet_multipliers(const std::function<void(Matrix&)>& apply,
                                               Index size, const ArnoldiOptions& options = {},
                                               const Eigen::MatrixXcd* warm = nullptr,
                                               Eigen::MatrixXcd* vectors = nullptr);

// An approximation K(σ) of M − σI for complex σ, applied inverted: z = K(σ)⁻¹ r. The open
// structure's monodromy M0 (every gap spring open) gives one in O(n) or O(n log n) a vector when
// the damping is classical (its 2 x 2 modal blocks).
using ShiftedInverse =
    std::function<Eigen::VectorXcd(const Eigen::VectorXcd& r, std::complex<double> sigma)>;

// The same multipliers as leading_floquet_multipliers, by a preconditioned Davidson iteration:
// the basis grows by the correction of the leading Ritz pair not yet converged (θ, u) with
// residual r = M u − θ u, t = −K(θ)⁻¹ r + ε K(θ)⁻¹ u, ε making t orthogonal to u (Olsen's
// correction: J. Olsen, P. Jørgensen and J. Simons, Chem. Phys. Lett. 169 (1990) 463-472; the
// method after E. R. Davidson, J. Comput. Phys. 17 (1975) 87-94, and as one step of Jacobi-
// Davidson, G. L. G. Sleijpen and H. A. van der Vorst, SIAM J. Matrix Anal. Appl. 17 (1996)
// 401-425). The basis is real: a complex correction enters by its real and imaginary parts, one
// block of two products. Rayleigh-Ritz on the basis gives the Ritz pairs, and their residuals are
// computed from the products, not estimated.
//
// Why. A lightly damped long chain's long waves crowd the unit circle: moduli 1 − 4e-6 k² at
// 1000 masses, 1 − 4e-8 k² at 10^4, at angles a few thousandths apart. Arnoldi separates them by
// modulus and needs a basis about as large as the crowd (590–690 products at 1000 masses, no
// convergence at 3000 or 10^4 in 200 vectors); K(θ)⁻¹ separates them by where they are in the
// plane, a shift-and-invert by the structure's linear part, so each converges in a few products
// whatever the crowd. Start: the warm Ritz vectors' real Schur vectors when given (the basis of
// their invariant subspace, as for Arnoldi), a fixed random vector and K(1)⁻¹ of it (the long
// waves, near 1). Restart at `krylov_dimension` columns to the span of the leading Ritz vectors,
// half the basis. Throws InputError for invalid options.
FloquetMultipliers preconditioned_floquet_multipliers(const std::function<void(Matrix&)>& apply,
                                                      const ShiftedInverse& inverse, Index size,
                                                      const ArnoldiOptions& options = {},
                                                      const Eigen::MatrixXcd* warm = nullptr,
                                                      Eigen::MatrixXcd* vectors = nullptr);

}  // namespace pwl::orbits
