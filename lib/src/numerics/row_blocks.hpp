#pragma once
// The blocks of rows of a banded operator and the substructure each is read off (He, Gao & Zhong,
// Appl. Math. Mech. 39(7) (2018) 737-749, §2): shared by the banded exponential
// (banded_exponential.cpp) and the banded switching PIM's force coefficients
// (banded_switching_pim.cpp), which must cut a structure the same way; private to pwl_core.
#include <vector>

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

}  // namespace pwl::banded_detail
