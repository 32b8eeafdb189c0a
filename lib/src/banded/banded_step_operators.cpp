// The banded step operators of the precise integration of He, Gao & Zhong, Appl. Math. Mech.
// 39(7) (2018) 737-749 (eqs 8-14 and 20-22), built from the banded exponential.
#include "pwl/integrators/banded_step_operators.hpp"

#include <algorithm>
#include <numeric>
#include <optional>

#include "banded/ordered_springs.hpp"
#include "banded/periodic_cut.hpp"
#include "pwl/numerics/substructure_exponential.hpp"

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
  const auto before = [&](Index a, Index b) { return position(a) < position(b); };
  // Builders list a chain's springs in order: one pass instead of a sort.
  if (!std::is_sorted(order.begin(), order.end(), before)) {
    std::stable_sort(order.begin(), order.end(), before);
  }
  return order;
}

namespace {

// The springs in spring_order: their gaps and stiffnesses, K2 W^T, and G_v = -M⁻¹W (the velocity
// rows of G), returned.
SparseMatrix set_springs(const GapStructure& structure, BandedStepOperators& ops) {
  banded_detail::OrderedSprings springs = banded_detail::ordered_springs(structure);
  ops.spring_order = std::move(springs.order);
  ops.gaps = std::move(springs.gaps);
  ops.stiffnesses = std::move(springs.stiffnesses);
  ops.gap_rows = banded_detail::scaled_rows(SparseMatrix(springs.directions.transpose()),
                                            ops.stiffnesses);
  return banded_detail::spring_accelerations(structure, springs.directions);
}

// Every row from its substructure.
BandedStepOperators build_row_by_row(const GapStructure& structure, double step,
                                     const BandedExponentialOptions& options) {
  BandedExponential e = make_banded_exponential(structure, step, options);
  BandedStepOperators ops;
  ops.step = step;
  ops.truncation = e.truncation;
  const SparseMatrix G = set_springs(structure, ops);
  ops.transition = std::move(e.transition);
  ops.force_next = multiply(e.rising_load, G);
  ops.force_now = multiply(e.falling_load, G);
  ops.harmonics = std::move(e.harmonics);
  // I - K2 W^T Φ_x, with Φ_x the displacement (even) rows of Φ.
  const BandedMatrix phi_x = select_rows(ops.force_next, 0, 2);
  const SparseMatrix minus_gap_rows = -ops.gap_rows;
  ops.lcp_matrix =
      add_diagonal(multiply(minus_gap_rows, phi_x), Vector::Ones(structure.spring_count()));
  return ops;
}

}  // namespace

BandedStepOperators make_banded_step_operators(const GapStructure& structure, double step,
                                               const BandedExponentialOptions& options) {
  banded_detail::check_banded_inputs(structure, step, options);
  BandedExponentialOptions band = options;
  if (band.cell_dofs == 0) band.cell_dofs = detect_cell_size(structure);
  // Construction from the period (periodic_cut.hpp): the banded operators of a short chain laid
  // out over this one; the springs' sparse parts are this structure's own.
  std::optional<BandedStepOperators> laid_out =
      banded_detail::build_from_period<BandedStepOperators>(
          structure, band,
          [&](const GapStructure& short_chain) {
            return build_row_by_row(short_chain, step, band);
          },
          [&](const BandedStepOperators& built, const banded_detail::PeriodicCut& cut,
              const AxisRepeat& springs) {
            const AxisRepeat state = banded_detail::state_axis(cut);
            BandedStepOperators ops;
            ops.step = step;
            ops.truncation = banded_detail::laid_out_truncation(built.truncation, cut);
            set_springs(structure, ops);
            ops.transition = repeat_period(built.transition, state, state);
            ops.force_next = repeat_period(built.force_next, state, springs);
            ops.force_now = repeat_period(built.force_now, state, springs);
            ops.harmonics = banded_detail::repeat_period(built.harmonics, state);
            ops.lcp_matrix = repeat_period(built.lcp_matrix, springs, springs);
            return ops;
          });
  if (laid_out) return std::move(*laid_out);
  return build_row_by_row(structure, step, band);
}

}  // namespace pwl
