// The banded step operators of the precise integration of He, Gao & Zhong, Appl. Math. Mech.
// 39(7) (2018) 737-749 (eqs 8-14 and 20-22), built from the banded exponential.
#include "pwl/integrators/banded_step_operators.hpp"

#include <algorithm>
#include <numeric>

#include "pwl/errors.hpp"

namespace pwl {

std::vector<Index> springs_by_position(const GapStructure& structure) {
  const auto& springs = structure.springs;
  std::vector<Index> order(springs.size());
  std::iota(order.begin(), order.end(), Index{0});
  const auto position = [&](Index j) {
    const GapSpring& s = springs[static_cast<std::size_t>(j)];
    const Index a = s.dof, b = s.other_dof >= 0 ? s.other_dof : s.dof;
    return std::pair{std::min(a, b), std::max(a, b)};
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](Index a, Index b) { return position(a) < position(b); });
  return order;
}

BandedStepOperators make_banded_step_operators(const GapStructure& structure, double step,
                                               const BandedExponentialOptions& options) {
  BandedExponential e = make_banded_exponential(structure, step, options);
  const Index n = structure.dofs();
  const Index m = structure.spring_count();

  BandedStepOperators ops;
  ops.step = step;
  ops.truncation = e.truncation;
  ops.spring_order = springs_by_position(structure);
  ops.gaps.resize(m);
  ops.stiffnesses.resize(m);
  // W in spring_order, and G_v = -M⁻¹W (the velocity rows of G).
  std::vector<Eigen::Triplet<double>> w, g, k2wt;
  const Vector mass = structure.mass.diagonal();
  for (Index j = 0; j < m; ++j) {
    const GapSpring& s = structure.springs[static_cast<std::size_t>(
        ops.spring_order[static_cast<std::size_t>(j)])];
    ops.gaps[j] = s.gap;
    ops.stiffnesses[j] = s.stiffness;
    const auto add = [&](Index dof, double direction) {
      g.emplace_back(dof, j, -direction / mass[dof]);
      k2wt.emplace_back(j, dof, s.stiffness * direction);
    };
    add(s.dof, s.direction);
    if (s.other_dof >= 0) add(s.other_dof, -s.direction);
  }
  SparseMatrix G(n, m);
  G.setFromTriplets(g.begin(), g.end());
  ops.gap_rows.resize(m, n);
  ops.gap_rows.setFromTriplets(k2wt.begin(), k2wt.end());

  ops.transition = std::move(e.transition);
  ops.force_next = multiply(e.rising_load, G);
  ops.force_now = multiply(e.falling_load, G);
  ops.harmonics = std::move(e.harmonics);
  // I - K2 W^T Φ_x, with Φ_x the displacement (even) rows of Φ.
  const BandedMatrix phi_x = select_rows(ops.force_next, 0, 2);
  const SparseMatrix minus_gap_rows = -ops.gap_rows;
  ops.lcp_matrix = add_diagonal(multiply(minus_gap_rows, phi_x), Vector::Ones(m));
  return ops;
}

}  // namespace pwl
