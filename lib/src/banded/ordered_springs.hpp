#pragma once
// The gap springs in the banded methods' order (springs_by_position: along the structure), as
// the sparse operators both banded steppers build their step from.
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/types.hpp"

namespace pwl::banded_detail {

struct OrderedSprings {
  std::vector<Index> order;  // spring j here is the structure's spring order[j]
  SparseMatrix directions;   // W, n x m: column j the direction of spring j
  Vector gaps, stiffnesses;  // Δ and k, m
};
OrderedSprings ordered_springs(const GapStructure& structure);

// -M⁻¹ W, the accelerations of unit spring forces (a diagonal mass).
SparseMatrix spring_accelerations(const GapStructure& structure, const SparseMatrix& W);

// diag(scale) A, in O(non-zeros) (Eigen's diagonal-times-sparse assignment inserts entry by
// entry).
SparseMatrix scaled_rows(const SparseMatrix& A, const Vector& scale);

}  // namespace pwl::banded_detail
