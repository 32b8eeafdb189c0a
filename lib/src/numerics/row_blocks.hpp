#pragma once
// The blocks of rows of a banded operator and the substructure each is read off (He, Gao & Zhong,
// Appl. Math. Mech. 39(7) (2018) 737-749, §2): shared by the banded exponential
// (banded_exponential.cpp) and the banded switching PIM's force coefficients
// (banded_switching_pim.cpp), which must cut a structure the same way; private to pwl_core.
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/types.hpp"

namespace pwl::banded_detail {

struct RowBlock {
  Index begin, end;                 // rows (degrees of freedom)
  Index window_first, window_last;  // the substructure
};

// Blocks of rows with their substructures (margin R each side, clamped at the ends). With a
// cell size p, the interior blocks are single cells, so that their substructures coincide in a
// periodic structure; the rows near each end form one block whose substructure holds that end.
std::vector<RowBlock> partition_rows(Index n, Index margin, Index cell);

// The banded methods' input checks, before anything is built: the options, the structure, a
// positive finite step and a diagonal mass (InputError naming the field otherwise). Shared by
// make_banded_exponential and make_banded_step_operators, which checks them before it builds
// from the period, so that an error names the long chain's fields.
void check_banded_inputs(const GapStructure& structure, double step,
                         const BandedExponentialOptions& options);

// Whether column j + p of A is column j shifted down by p (rows and values).
bool shifted_column_matches(const SparseMatrix& A, Index j, Index p);

// Which windows repeat exactly the window `shift()` degrees of freedom before them, found in
// O(non-zeros) once, so that the blocks of a periodic stretch reuse an earlier block's
// substructure without building and hashing a SubstructureKey each (what made the assembly's
// cost per mass). The shift is the smallest multiple of the cell, up to 8 cells, under which the
// middle half of the structure repeats with its loads (the paper's chain: cells of one mass,
// loads alternating, shift 2). A degree of freedom repeats the one `shift` before it when its
// columns of M, C and K (entries as offsets from the diagonal, with their values) and its loads
// are the same; a window whose degrees of freedom all repeat holds the content of the window
// `shift` before it (the entries it keeps are the same offsets from the same places).
// Sufficient, not necessary: a window that fails simply takes the key lookup.
class CellRepeats {
 public:
  CellRepeats(const GapStructure& structure, Index cell, const std::vector<LoadGroup>& loads);
  Index shift() const { return shift_; }
  // True when degree of freedom i carries what i - shift() carries (M, C, K and loads).
  bool dof_repeats(Index i) const {
    return shift_ > 0 && i >= shift_ &&
           differing_[static_cast<std::size_t>(i + 1)] == differing_[static_cast<std::size_t>(i)];
  }
  // True when window [first, last) holds exactly the content of [first - shift, last - shift).
  bool repeats_earlier(Index first, Index last) const {
    return shift_ > 0 && first >= shift_ &&
           differing_[static_cast<std::size_t>(last)] == differing_[static_cast<std::size_t>(first)];
  }

 private:
  Index shift_ = 0;
  std::vector<Index> differing_;  // differing_[i]: degrees of freedom below i that do not repeat
};

// True when `block` is `earlier` shifted by repeats.shift() along a stretch that repeats, so that
// both read their rows off the same substructure at the same place.
inline bool repeats_block(const RowBlock& earlier, const RowBlock& block,
                          const CellRepeats& repeats) {
  const Index shift = repeats.shift();
  return block.window_first - earlier.window_first == shift &&
         block.window_last - earlier.window_last == shift &&
         block.end - block.begin == earlier.end - earlier.begin &&
         block.begin - block.window_first == earlier.begin - earlier.window_first &&
         repeats.repeats_earlier(block.window_first, block.window_last);
}

}  // namespace pwl::banded_detail
