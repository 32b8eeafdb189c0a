#pragma once
// The exponential of a substructure: the degrees of freedom [first, last) of a structure with
// every other degree of freedom held fixed (the principal submatrices of M, C and K).
//
// Energy travels a finite distance in one step (He, Gao & Zhong 2018, §2, figure 3): an impulse
// at a degree of freedom j reaches only its neighbours within a few cells in a time η, and the
// entries T_ij of exp(Hη) fall off faster than exponentially with |i - j|. A substructure that
// reaches far enough beyond row i on both sides therefore has the same row i of its exponential
// as the whole structure, to within what travels out to the cut and back: the entries of T at
// twice that distance. Rows of the whole structure's exponential are read off such
// substructures, each a few cells wide, so the cost does not depend on the structure's size
// (banded_exponential.hpp).
//
// Everything a precise-integration step needs comes out of the same 2^N doublings (Zhong &
// Williams, Proc. IMechE C 208 (1994) 427-430; precise_exponential.hpp), applied to a unit
// acceleration at every degree of freedom of the substructure, i.e. to the columns of [0; I]:
//
//   rising_load  = (Γ0 - Γ1/η) [0; I]   response to a load rising linearly from 0 to 1 over the
//                                        step (it multiplies the spring forces P_{k+1})
//   falling_load = (Γ1/η) [0; I]         a load falling linearly from 1 to 0 (multiplies P_k)
//
// and to the harmonic loads that act on the substructure, through Kω applied to [0; M⁻¹ f] for
// the sine and cosine parts of each load group (two columns per frequency rather than one per
// degree of freedom): the exact response over one step to every load within the substructure.
// The springs are applied later (banded_step_operators.hpp), so they do not enter the
// substructure. SubstructureKey captures exactly the content that does (M, C, K and the loads on
// the window), so that a periodic structure computes each distinct substructure once.
#include <cstddef>
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

// The content of M, C and K on the window [first, last): the window's size and every non-zero
// entry of the three principal submatrices with its position relative to the window, and the
// load groups' entries on the window. Equal keys mean equal substructure exponentials (for the
// same step).
class SubstructureKey {
 public:
  SubstructureKey() = default;
  // Throws InputError for a window outside 0..dofs.
  SubstructureKey(const GapStructure& structure, Index first, Index last,
                  const std::vector<LoadGroup>& loads = {});
  std::size_t hash() const { return hash_; }
  bool operator==(const SubstructureKey& other) const {
    return hash_ == other.hash_ && content_ == other.content_;
  }
  struct Hasher {
    std::size_t operator()(const SubstructureKey& k) const { return k.hash(); }
  };

 private:
  std::vector<double> content_;
  std::size_t hash_ = 0;
};

struct SubstructureExponential {
  Index first = 0;  // the window's first degree of freedom in the whole structure
  Index size = 0;   // w: its number of degrees of freedom
  // In the substructure's own state layout [x; x'] (x in rows 0..w-1, x' in rows w..2w-1).
  Matrix transition;    // T = exp(Hη), 2w x 2w
  Matrix rising_load;   // (Γ0 - Γ1/η) [0; I], 2w x w
  Matrix falling_load;  // (Γ1/η) [0; I], 2w x w
  // Per load group, the exact response over a step starting at t_k to the group's loads on the
  // window: add sin(ωt_k) sin_response + cos(ωt_k) cos_response (2w each).
  std::vector<HarmonicResponse> harmonics;
};

// The exponential and load integrals of the substructure [first, last) for step η, with the
// responses to the given load groups (whole-structure vectors; their entries on the window are
// used). Throws InputError for an empty or out-of-range window, a bad step or load sizes.
SubstructureExponential substructure_exponential(const GapStructure& structure, Index first,
                                                 Index last, double step,
                                                 const std::vector<LoadGroup>& loads = {},
                                                 const PreciseExponentialOptions& options = {});

// The substructure's state matrix H = [[0, I], [-M⁻¹K, -M⁻¹C]] (dense, 2w x 2w).
Matrix substructure_state_matrix(const GapStructure& structure, Index first, Index last);

// The smallest p in 1..max_cell for which M, C and K repeat with period p in the middle half of
// the structure (column j + p is column j shifted by p), or 0 if none does. The cells of the
// paper's chain have p = 1. Only used to choose which rows share a substructure; the result is
// exact whatever it returns.
Index detect_cell_size(const GapStructure& structure, Index max_cell = 16);

}  // namespace pwl
