#pragma once
// The banded exponential of a chain-like structure: T = exp(Hη) and the step's load integrals as
// banded matrices, assembled row by row from the exponentials of small substructures (He, Gao &
// Zhong 2018, §2, the equations lost from the extracted text; SPEC.md §4).
//
// The band. Each n x n block of T (and of the load integrals) has entries that fall off faster
// than exponentially with the distance |i - j| between degrees of freedom. The band q is the
// smallest distance for which what is dropped is below a tolerance:
//
//     for every operator block B and every row i:  Σ_{|i-j| > q} |B_ij|  <=  tol · ‖B‖∞,
//
// so that, e.g., the displacements of T v change by at most tol (‖T_xx‖∞ ‖x‖∞ + ‖T_xv‖∞ ‖x'‖∞).
// The blocks are those of T (x from x, x from x', x' from x, x' from x') and the displacement and
// velocity rows of the two linear-load integrals. The dropped sums are measured on every row's
// substructure while it is assembled (entries beyond the substructure are smaller still, as they
// keep falling off), and the largest ratio is reported as BandTruncation::dropped_ratio.
// Default tol = 1e-15. The harmonic loads need no band: each row's exact response over a step is
// read off its substructure, with every load inside it (those beyond it act through entries
// smaller than the dropped ones).
//
// The substructures. Rows are taken in blocks; a block's substructure reaches a margin of
// R = q + guard degrees of freedom beyond it on each side (clamped at the real ends, where the
// substructure contains the end). What the cut changes in a kept entry T_ij is what travels from
// j to the cut and back to i, i.e. entries at distance >= 2R + 2 - q > q + guard: below the
// dropped ones. For a periodic structure (cells of p degrees of freedom, detected or declared)
// every interior block is one cell and its substructure is the same (2R + p)-dof piece, computed
// once: the paper's "interior band from the middle of a (2q+1)-cell substructure", with one more
// substructure for the rows near each end. When cells differ along the chain (masses,
// stiffnesses or dampers that vary), the blocks are ~R rows and each has its own substructure;
// substructures with equal content are still computed once.
//
// Storage: the state is interleaved, [x_0, x_0', x_1, x_1', ...]. Row i of T couples x_i and x_i'
// to the displacements and velocities of the 2q+1 nearest degrees of freedom; interleaved, these
// are one run of 4q+2 consecutive columns, so a step is a single unit-stride sweep over one
// banded matrix (half-bandwidth 2q+1) instead of four sweeps over four blocks that read the state
// in two places, and the displacement rows the LCP needs are simply the even rows.
//
// Requires a diagonal (lumped) mass matrix: with a consistent mass matrix M⁻¹K is not banded.
#include <string>
#include <vector>

#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

// Index of x_dof (derivative 0) or x_dof' (derivative 1) in the interleaved state.
inline Index state_index(Index dof, int derivative) { return 2 * dof + derivative; }
// [x_0, x_0', x_1, x_1', ...] from x and x', and back.
Vector interleave_state(const Vector& x, const Vector& v);
void deinterleave_state(const Vector& state, Vector& x, Vector& v);

struct BandedExponentialOptions {
  double tolerance = 1e-15;  // dropped part of every operator block relative to its ∞-norm
  Index band = 0;            // q in degrees of freedom; 0: the smallest q within the tolerance
  Index guard = 1;           // dofs of substructure beyond the band on each side (R = q + guard)
  Index cell_dofs = 0;       // cell size of a periodic structure; 0: detect it
  Index max_band = 512;      // give up (InputError) rather than grow q beyond this
  bool share_rows = true;    // store identical rows once (BandedMatrix)
  // Construction from the period, for the steppers' operator sets (make_banded_step_operators,
  // make_banded_switching_pim; make_banded_exponential alone always builds row by row): where
  // the middle of a chain repeats (masses, dampers, springs, the gap springs' directions and
  // stiffnesses, loads), the operators are computed for a short chain with the same ends, its
  // middle cut down to the reach of a row, and the long chain's rows laid out from it. Their
  // entries are bit for bit those of the row-by-row build, and the construction no longer grows
  // with the chain's length except for one pass over its rows (lib/src/banded/periodic_cut.hpp).
  // Needs share_rows. false: every row built from its substructure.
  bool from_period = true;
  // N and the Taylor order of every substructure. The doublings are trimmed to those the
  // substructure needs (precise_exponential.hpp), and a series of order 8 needs fewer of them:
  // at η = 0.2 s a window of the paper's chain (‖Hη‖ = 0.96) runs 6 doublings of order 8 with
  // its loads (ω up to 5 rad/s) and 5 for the switching PIM's force moments, where the paper's
  // N = 20 of order 4 ran 20, all exact to rounding. This was about a third of the switching
  // PIM's construction at n = 1000.
  PreciseExponentialOptions exponential{.taylor_order = 8, .trim_doublings = true};
  bool is_valid(std::string* why) const;
};

// What the band dropped and what it cost.
struct BandTruncation {
  double tolerance = 0.0;
  Index band = 0;              // q (degrees of freedom)
  Index margin = 0;            // R: substructure reach beyond its rows on each side
  Index cell_dofs = 0;         // period used for the row blocks (0: none found)
  double dropped_ratio = 0.0;  // measured max over blocks and rows of dropped / ‖block‖∞
  std::string worst_block;     // the block where it is largest
  Index blocks = 0;            // row blocks, one substructure each
  Index exponentials = 0;      // substructure exponentials actually computed (distinct content)
  Index largest_substructure = 0;  // dofs
  int assemblies = 0;          // more than 1 when the band outgrew the first margin
  Index probe_reach = 0;       // dofs around the middle row read to probe the first margin
  Index laid_out = 0;          // dofs whose rows were laid out from the period, not built
  bool within_tolerance() const { return dropped_ratio <= tolerance; }
};

struct BandedExponential {
  double step = 0.0;
  // All on the interleaved state (2n rows); the load integrals have one column per degree of
  // freedom (a unit acceleration there).
  BandedMatrix transition;    // T = exp(Hη), 2n x 2n
  BandedMatrix rising_load;   // (Γ0 - Γ1/η) [0; I], 2n x n
  BandedMatrix falling_load;  // (Γ1/η) [0; I], 2n x n
  // The exact response to each load group over one step from t_k (as in pim_step_operators.hpp):
  // add sin(ωt_k) sin_response + cos(ωt_k) cos_response. Interleaved, 2n.
  std::vector<HarmonicResponse> harmonics;
  BandTruncation truncation;
};

// Throws InputError for an invalid structure, step or options, for a mass matrix that is not
// diagonal, or when no band up to max_band meets the tolerance.
BandedExponential make_banded_exponential(const GapStructure& structure, double step,
                                          const BandedExponentialOptions& options = {});

}  // namespace pwl
