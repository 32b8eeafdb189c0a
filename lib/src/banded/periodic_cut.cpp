// Construction from the period (periodic_cut.hpp): He, Gao & Zhong, Appl. Math. Mech. 39(7)
// (2018) 737-749, §2, where the operators of a periodic structure are read off one substructure;
// here the whole set of a chain's step operators is read off a short chain with the same ends.
#include "banded/periodic_cut.hpp"

#include <algorithm>

#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/integrators/banded_step_operators.hpp"

namespace pwl::banded_detail {
namespace {

Index first_end(const GapSpring& g) {
  return g.other_dof >= 0 ? std::min(g.dof, g.other_dof) : g.dof;
}

// The springs by their first degree of freedom: those of dof i are order[first[i] .. first[i+1])
// (springs_by_position sorts by the first end).
struct SpringsByDof {
  std::vector<Index> order, first;
  explicit SpringsByDof(const GapStructure& s)
      : order(springs_by_position(s)), first(static_cast<std::size_t>(s.dofs() + 1), 0) {
    for (const GapSpring& g : s.springs) ++first[static_cast<std::size_t>(first_end(g) + 1)];
    for (std::size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
  }
  // Whether dof i carries the springs of dof i - p as the banded operators see them, from their
  // first ends: the offsets of their ends (ground alike), directions and stiffnesses, in the
  // same order. (Not the gaps: no banded operator reads them.)
  bool repeats(const GapStructure& s, Index i, Index p) const {
    const auto at = [&](Index dof) { return first[static_cast<std::size_t>(dof)]; };
    const auto spring = [&](Index k) -> const GapSpring& {
      return s.springs[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])];
    };
    const Index count = at(i + 1) - at(i);
    if (count != at(i - p + 1) - at(i - p)) return false;
    for (Index k = 0; k < count; ++k) {
      const GapSpring& a = spring(at(i) + k);
      const GapSpring& b = spring(at(i - p) + k);
      const bool same_other =
          (a.other_dof < 0 && b.other_dof < 0) ||
          (a.other_dof >= 0 && b.other_dof >= 0 && a.other_dof - b.other_dof == p);
      if (a.dof - b.dof != p || !same_other || a.direction != b.direction ||
          a.stiffness != b.stiffness) {
        return false;
      }
    }
    return true;
  }
};

}  // namespace

std::optional<PeriodicCut> find_periodic_cut(const GapStructure& s, const CellRepeats& repeats,
                                             Index margin) {
  const Index n = s.dofs();
  const Index base = repeats.shift();
  const BandedLayout layout = banded_layout(s);
  if (base <= 0 || margin <= 0 || !layout.diagonal_mass) return std::nullopt;
  const Index span = std::max(layout.dof_bandwidth, layout.spring_reach);
  const SpringsByDof springs(s);
  const Index mid = n / 2;
  // M, C, K and the loads repeat with `base` over [run_first - base, run_last); within it they
  // repeat with any multiple of base, which the gap springs may need.
  if (!repeats.dof_repeats(mid)) return std::nullopt;
  Index run_first = mid, run_last = mid + 1;
  while (run_first - 1 >= base && repeats.dof_repeats(run_first - 1)) --run_first;
  while (run_last < n && repeats.dof_repeats(run_last)) ++run_last;
  const Index a0 = run_first - base;
  for (Index k = 1; k <= 8; ++k) {
    const Index period = k * base;
    const auto both = [&](Index i) {
      return i - period >= a0 && i < run_last && springs.repeats(s, i, period);
    };
    if (!both(mid)) continue;
    Index first = mid, last = mid + 1;
    while (both(first - 1)) --first;
    while (both(last)) ++last;
    PeriodicCut cut;
    cut.period = period;
    cut.margin = margin;
    cut.span = span;
    cut.periodic_first = first - period;  // [a, b) repeats with the period
    cut.periodic_last = last;
    cut.cut = cut.periodic_first + margin;
    const Index room = cut.periodic_last - margin - cut.cut;
    cut.removed = room > 0 ? room / (2 * period) * (2 * period) : 0;
    // Worth it only when a quarter of the chain goes (else a longer period may repeat over a
    // longer stretch: springs on every fifth cell); the couplings across the cut must not reach
    // over the whole removed stretch, nor the kept margin.
    if (margin <= span) return std::nullopt;
    if (cut.removed >= n / 4 && cut.removed > span) return cut;
  }
  return std::nullopt;
}

GapStructure shorten(const GapStructure& s, const PeriodicCut& cut) {
  const Index c = cut.cut, D = cut.removed, n = s.dofs();
  // Where degree of freedom pair (i, j) of the long chain goes in the short one: kept before the
  // cut, moved D back after it, and a pair from the removed stretch to beyond it stands in for
  // the pair across the cut (the same content, one whole number of periods on); false: left out.
  const auto place = [&](Index i, Index j, Index& si, Index& sj) {
    const Index lo = std::min(i, j), hi = std::max(i, j);
    if (hi < c) {
      si = i;
      sj = j;
      return true;
    }
    if (lo >= c && hi >= c + D) {
      si = i - D;
      sj = j - D;
      return true;
    }
    return false;
  };
  const auto cut_matrix = [&](const SparseMatrix& A) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(A.nonZeros()));
    for (Index j = 0; j < A.outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
        Index si = 0, sj = 0;
        if (place(it.row(), j, si, sj)) t.emplace_back(si, sj, it.value());
      }
    }
    SparseMatrix B(n - D, n - D);
    B.setFromTriplets(t.begin(), t.end());
    return B;
  };
  GapStructure out;
  out.mass = cut_matrix(s.mass);
  out.damping = cut_matrix(s.damping);
  out.stiffness = cut_matrix(s.stiffness);
  for (const GapSpring& g : s.springs) {
    Index a = 0, b = 0;
    if (place(g.dof, g.other_dof >= 0 ? g.other_dof : g.dof, a, b)) {
      GapSpring h = g;
      h.dof = static_cast<int>(a);
      if (g.other_dof >= 0) h.other_dof = static_cast<int>(b);
      out.springs.push_back(h);
    }
  }
  for (const HarmonicLoad& l : s.loads) {
    Index a = 0, b = 0;
    if (place(l.dof, l.dof, a, b)) {
      HarmonicLoad k = l;
      k.dof = static_cast<int>(a);
      out.loads.push_back(k);
    }
  }
  return out;
}

bool reach_fits(const PeriodicCut& cut, Index short_dofs, Index reach) {
  const Index a = cut.periodic_first, c = cut.cut;
  const Index short_last = cut.periodic_last - cut.removed;  // the short chain's periodic end
  const Index long_mid = (short_dofs + cut.removed) / 2, short_mid = short_dofs / 2;
  // The repeated rows [c - P, c) and the rows on both sides of the cut, then the middle rows
  // where the band is probed (the same phase in the period, D being a multiple of 2P).
  return c - cut.period - reach >= a && c + reach <= short_last && short_mid - reach >= a &&
         short_mid + reach <= short_last && long_mid - reach >= a &&
         long_mid + reach <= cut.periodic_last;
}

AxisRepeat state_axis(const PeriodicCut& cut) {
  return {2 * cut.cut, 2 * cut.period, cut.removed / cut.period};
}

AxisRepeat spring_axis(const GapStructure& short_structure, const PeriodicCut& cut) {
  Index before = 0, period = 0;
  for (const GapSpring& g : short_structure.springs) {
    const Index p = first_end(g);
    if (p < cut.cut) ++before;
    if (p < cut.cut && p >= cut.cut - cut.period) ++period;
  }
  return {before, period, cut.removed / cut.period};
}

Vector repeat_period(const Vector& v, const AxisRepeat& axis) {
  Vector out(v.size() + axis.inserted());
  out.head(axis.before) = v.head(axis.before);
  for (Index k = 0; k < axis.copies; ++k) {
    out.segment(axis.before + k * axis.period, axis.period) =
        v.segment(axis.before - axis.period, axis.period);
  }
  out.tail(v.size() - axis.before) = v.tail(v.size() - axis.before);
  return out;
}

std::vector<HarmonicResponse> repeat_period(const std::vector<HarmonicResponse>& harmonics,
                                            const AxisRepeat& state) {
  std::vector<HarmonicResponse> out;
  out.reserve(harmonics.size());
  for (const HarmonicResponse& h : harmonics) {
    out.push_back(
        {h.omega, repeat_period(h.sin_response, state), repeat_period(h.cos_response, state)});
  }
  return out;
}

BandTruncation laid_out_truncation(const BandTruncation& built, const PeriodicCut& cut) {
  BandTruncation t = built;
  // One row block (a cell) per cell of the removed stretch.
  if (t.cell_dofs > 0) t.blocks += cut.removed / t.cell_dofs;
  t.laid_out = cut.removed;
  return t;
}

}  // namespace pwl::banded_detail
