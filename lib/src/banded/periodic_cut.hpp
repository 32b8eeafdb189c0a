#pragma once
// Construction from the period: the banded operators of a long chain built on a short one.
//
// Every row of the banded step operators (T, the load responses, the switching PIM's force
// moments and their products with the spring directions, the LCP matrix) is read off a small
// substructure around its degree of freedom (He, Gao & Zhong, Appl. Math. Mech. 39(7) (2018)
// 737-749, §2). In a stretch where the structure repeats with a period of P degrees of freedom,
// the rows therefore repeat too, one period further each P degrees of freedom. So a chain of
// n masses whose middle repeats needs its operators computed only for a short chain, the same
// chain with D = k·P degrees of freedom of that middle cut out: the rows before the cut are the
// short chain's, the rows after it are the short chain's moved D on, and the D cut rows are the
// short chain's last period before the cut, repeated. The work of the construction is then that
// of the short chain (its length is set by the band and the substructures, not by n) plus one
// pass over the rows to lay them out.
//
// Exactness. The short chain is built so that around the cut its content (masses, dampers,
// springs, gap springs, loads) is that of the long chain's periodic middle, degree of freedom by
// degree of freedom. A row is computed from the content within its reach (the substructure of
// its block, the band, the springs' spans), so when every row near the cut has its reach inside
// the periodic stretch, each row of the short chain is bit for bit the long chain's row at the
// same place: the same substructure, the same operations in the same order. The caller checks
// the reach after building the short chain (`reach_fits`) and builds the long chain directly
// when it does not fit.
#include <cstdlib>
#include <optional>
#include <vector>

#include "numerics/row_blocks.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/types.hpp"

namespace pwl::banded_detail {

// Degrees of freedom [cut, cut + removed) of the long chain are left out of the short one.
struct PeriodicCut {
  Index period = 0;        // P: the structure repeats P degrees of freedom on
  Index cut = 0;           // first degree of freedom left out
  Index removed = 0;       // D, a multiple of 2P (so the short chain's middle row has the long
                           // one's phase in the period)
  Index margin = 0;        // periodic degrees of freedom kept on each side of the cut
  Index span = 0;          // widest coupling |i - j| of M, C, K and the gap springs
  Index periodic_first = 0, periodic_last = 0;  // the long chain's periodic stretch [a, b)
};

// A cut that keeps `margin` periodic degrees of freedom on each side, with period `period`
// (loads, springs and M, C, K all repeat), in the periodic stretch around the chain's middle.
// nullopt when the stretch is too short to leave out at least a quarter of the chain.
std::optional<PeriodicCut> find_periodic_cut(const GapStructure& structure, Index period,
                                             Index margin);

// The short chain: the long one without [cut, cut + removed), the couplings and springs across
// the cut taken from those across its far end.
GapStructure shorten(const GapStructure& structure, const PeriodicCut& cut);

// True when rows whose content reaches `reach` degrees of freedom around them (and the short
// chain's middle row, where the band is probed) are unaffected by the cut.
bool reach_fits(const PeriodicCut& cut, Index short_dofs, Index reach);

// The cut along one axis of an operator: `before` rows (or columns) precede it in the short
// operator, `period` of them make one period, and `copies` periods are inserted.
AxisRepeat axis_repeat(const PeriodicCut& cut, Index units_before, Index units_per_period);

// An axis counted in springs, ordered by position (springs_by_position) in the short chain.
AxisRepeat spring_axis(const GapStructure& short_structure, const PeriodicCut& cut);

// A vector on the state (2 entries per degree of freedom) of the short chain, the cut refilled.
Vector repeat_period(const Vector& v, const AxisRepeat& axis);

// True when M has no non-zero off its diagonal (the banded methods' requirement; a structure
// without it goes to the row-by-row build, which reports it).
bool diagonal_mass(const GapStructure& structure);

// An operator set (T, the load responses, ...: a type with `truncation` and `harmonics` members)
// of a long chain, from the period: `build(short_chain)` gives the short chain's set,
// `layout(set, cut, springs)` lays it out over the long chain (springs: the spring axis of the
// short chain). nullopt when the chain has no periodic middle that saves a quarter of it, when
// its mass is not diagonal, or when the reach of the built rows does not fit the cut even after
// one rebuild with a cut made for that reach: the caller then builds row by row.
template <class Set, class Build, class Layout>
std::optional<Set> build_from_period(const GapStructure& s, const BandedExponentialOptions& band,
                                     const Build& build, const Layout& layout) {
  if (!band.from_period || !band.share_rows || band.cell_dofs <= 0 || !diagonal_mass(s)) {
    return std::nullopt;
  }
  const std::vector<LoadGroup> loads = s.load_groups();
  const Index period = CellRepeats(s, band.cell_dofs, loads).shift();
  // A first guess at the degrees of freedom each side of the cut must keep; the reach the built
  // operators need is checked after, and the build redone once with that reach.
  Index margin = std::max<Index>(64, 8 * period);
  for (int attempt = 0; attempt < 2; ++attempt) {
    const std::optional<PeriodicCut> cut = find_periodic_cut(s, period, margin);
    if (!cut) return std::nullopt;
    const GapStructure short_chain = shorten(s, *cut);
    Set built = build(short_chain);
    // What one row reads: its block's substructure (margin R beyond a cell), the band q of the
    // operators, the springs' spans on both sides of the products with W, and the probe of the
    // band (up to 2R around the middle row).
    const BandTruncation& t = built.truncation;
    const Index reach = 2 * t.margin + 2 * t.cell_dofs + 2 * t.band + 2 * cut->span + 8;
    bool same_loads = built.harmonics.size() == loads.size();
    for (std::size_t g = 0; same_loads && g < loads.size(); ++g) {
      same_loads = built.harmonics[g].omega == loads[g].omega;
    }
    if (!same_loads) return std::nullopt;
    if (reach_fits(*cut, short_chain.dofs(), reach)) {
      return layout(built, *cut, spring_axis(short_chain, *cut));
    }
    // Enough for the reach, the repeated period and the middle row, wherever the short chain's
    // non-periodic ends make its middle fall.
    const Index front = cut->periodic_first, back = s.dofs() - cut->periodic_last;
    margin = reach + 3 * period + std::abs(front - back) / 2 + 2;
  }
  return std::nullopt;
}

}  // namespace pwl::banded_detail
