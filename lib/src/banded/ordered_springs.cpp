// The gap springs in the banded methods' order (ordered_springs.hpp).
#include "banded/ordered_springs.hpp"

#include "pwl/integrators/banded_step_operators.hpp"

namespace pwl::banded_detail {

OrderedSprings ordered_springs(const GapStructure& s) {
  const Index m = s.spring_count();
  OrderedSprings out{springs_by_position(s), SparseMatrix(s.dofs(), m), Vector(m), Vector(m)};
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(static_cast<std::size_t>(2 * m));
  for (Index j = 0; j < m; ++j) {
    const GapSpring& g =
        s.springs[static_cast<std::size_t>(out.order[static_cast<std::size_t>(j)])];
    out.gaps[j] = g.gap;
    out.stiffnesses[j] = g.stiffness;
    w.emplace_back(g.dof, j, g.direction);
    if (g.other_dof >= 0) w.emplace_back(g.other_dof, j, -g.direction);
  }
  out.directions.setFromTriplets(w.begin(), w.end());
  return out;
}

SparseMatrix scaled_rows(const SparseMatrix& A, const Vector& scale) {
  SparseMatrix B = A;
  for (Index j = 0; j < B.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(B, j); it; ++it) it.valueRef() *= scale[it.row()];
  }
  return B;
}

SparseMatrix spring_accelerations(const GapStructure& s, const SparseMatrix& W) {
  return scaled_rows(W, -s.mass.diagonal().cwiseInverse());
}

}  // namespace pwl::banded_detail
