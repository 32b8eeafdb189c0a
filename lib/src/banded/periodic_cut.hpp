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
// springs, the gap springs' directions and stiffnesses, loads) is that of the long chain's
// periodic middle, degree of freedom by degree of freedom. A row is computed from the content
// within its reach (the substructure of its block, the band, the springs' spans), so when every
// row near the cut has its reach inside the periodic stretch, each row of the short chain is bit
// for bit the long chain's row at the same place: the same substructure, the same operations in
// the same order (the substructures' exponentials keep their products on one thread whatever
// the chunk they are computed in: banded_exponential.cpp). The entries laid out are therefore
// those of the row-by-row build, bit for bit; only where a row is all zeros may its stored first
// column differ. The caller checks the reach after building the short chain (build_from_period)
// and builds the long chain row by row when it does not fit. The gaps enter no banded operator
// (only the step's right-hand sides, which keep the long chain's own), so they need not repeat.
#include <algorithm>
#include <cstdlib>
#include <optional>
#include <vector>

#include "numerics/row_blocks.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/types.hpp"

namespace pwl::banded_detail {

// Degrees of freedom [cut, cut + removed) of the long chain are left out of the short one.
struct PeriodicCut {
  Index period = 0;   // P: the structure repeats P degrees of freedom on
  Index cut = 0;      // first degree of freedom left out
  Index removed = 0;  // D, a multiple of 2P (so the short chain's middle row has the long
                      // one's phase in the period)
  Index margin = 0;   // periodic degrees of freedom kept on each side of the cut
  Index span = 0;     // widest coupling |i - j| of C, K and the gap springs
  Index periodic_first = 0, periodic_last = 0;  // the long chain's periodic stretch [a, b)
};

// A cut that keeps `margin` periodic degrees of freedom on each side, in the stretch around the
// chain's middle where M, C, K and the loads repeat with repeats.shift() (or a multiple of it,
// up to 8, where the gap springs repeat only with that). nullopt when no such stretch saves at
// least a quarter of the chain.
std::optional<PeriodicCut> find_periodic_cut(const GapStructure& structure,
                                             const CellRepeats& repeats, Index margin);

// The short chain: the long one without [cut, cut + removed), the couplings and springs across
// the cut taken from those across its far end.
GapStructure shorten(const GapStructure& structure, const PeriodicCut& cut);

// True when rows whose content reaches `reach` degrees of freedom around them (and the short
// chain's middle row, where the band is probed) are unaffected by the cut.
bool reach_fits(const PeriodicCut& cut, Index short_dofs, Index reach);

// The cut along the interleaved state (2 rows per degree of freedom).
AxisRepeat state_axis(const PeriodicCut& cut);
// The cut along the springs, ordered by position (springs_by_position) in the short chain.
AxisRepeat spring_axis(const GapStructure& short_structure, const PeriodicCut& cut);

// A vector on an axis of the short chain, the cut refilled.
Vector repeat_period(const Vector& v, const AxisRepeat& axis);
// The harmonic responses (interleaved state) of the short chain, laid out over the long one.
std::vector<HarmonicResponse> repeat_period(const std::vector<HarmonicResponse>& harmonics,
                                            const AxisRepeat& state);
// The short chain's truncation report as the long chain's: its row blocks counted over the long
// chain, and the degrees of freedom laid out.
BandTruncation laid_out_truncation(const BandTruncation& built, const PeriodicCut& cut);

// An operator set (a type with `truncation` and `harmonics` members) of a long chain, from the
// period: `build(short_chain)` gives the short chain's set, `layout(set, cut, springs)` lays it
// out over the long chain (springs: the spring axis of the short chain). nullopt when the chain
// has no periodic middle that saves a quarter of it, when its mass is not diagonal, or when the
// reach of the built rows does not fit the cut even after one rebuild with a cut made for that
// reach: the caller then builds row by row.
template <class Set, class Build, class Layout>
std::optional<Set> build_from_period(const GapStructure& s, const BandedExponentialOptions& band,
                                     const Build& build, const Layout& layout) {
  if (!band.from_period || !band.share_rows || band.cell_dofs <= 0) return std::nullopt;
  const std::vector<LoadGroup> loads = s.load_groups();
  const CellRepeats repeats(s, band.cell_dofs, loads);
  // A first guess at the degrees of freedom each side of the cut must keep; the reach the built
  // operators need is checked after, and the build redone once with that reach.
  Index margin = std::max<Index>(64, 8 * repeats.shift());
  for (int attempt = 0; attempt < 2; ++attempt) {
    const std::optional<PeriodicCut> cut = find_periodic_cut(s, repeats, margin);
    if (!cut) return std::nullopt;
    const GapStructure short_chain = shorten(s, *cut);
    Set built = build(short_chain);
    // What one row reads: its block's substructure (margin R beyond a cell), the band q of the
    // operators, the springs' spans on both sides of the products with W; and what the probe of
    // the band read around the middle row.
    const BandTruncation& t = built.truncation;
    const Index reach =
        std::max(2 * t.margin + 2 * t.cell_dofs + 2 * t.band + 2 * cut->span, t.probe_reach) + 8;
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
    margin = reach + 3 * cut->period + std::abs(front - back) / 2 + 2;
  }
  return std::nullopt;
}

}  // namespace pwl::banded_detail
