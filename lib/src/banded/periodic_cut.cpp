// Construction from the period (periodic_cut.hpp): He, Gao & Zhong, Appl. Math. Mech. 39(7)
// (2018) 737-749, §2, where the operators of a periodic structure are read off one substructure;
// here the whole set of a chain's step operators is read off a short chain with the same ends.
#include "banded/periodic_cut.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "numerics/row_blocks.hpp"
#include "pwl/errors.hpp"
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
  // Whether dof i carries the springs of dof i - p, seen from their first ends: the offsets of
  // their ends (ground alike), directions, stiffnesses and gaps, in the same order.
  bool repeats(const GapStructure& s, Index i, Index p) const {
    const auto at = [&](Index dof) { return first[static_cast<std::size_t>(dof)]; };
    if (at(i + 1) - at(i) != at(i - p + 1) - at(i - p)) return false;
    for (Index k = 0; k < at(i + 1) - at(i); ++k) {
      const GapSpring& a = s.springs[static_cast<std::size_t>(order[static_cast<std::size_t>(at(i) + k)])];
      const GapSpring& b =
          s.springs[static_cast<std::size_t>(order[static_cast<std::size_t>(at(i - p) + k)])];
      const bool same_other = (a.other_dof < 0 && b.other_dof < 0) ||
                              (a.other_dof >= 0 && b.other_dof >= 0 && a.other_dof - i == b.other_dof - (i - p));
      if (a.dof - i != b.dof - (i - p) || !same_other || a.direction != b.direction ||
          a.stiffness != b.stiffness || a.gap != b.gap) {
        return false;
      }
    }
    return true;
  }
};

// The widest coupling: |i - j| over the non-zeros of M, C, K and the spring ends.
Index coupling_span(const GapStructure& s) {
  Index span = 0;
  for (const SparseMatrix* A : {&s.mass, &s.damping, &s.stiffness}) {
    for (Index j = 0; j < A->outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(*A, j); it; ++it) {
        span = std::max(span, std::abs(it.row() - j));
      }
    }
  }
  for (const GapSpring& g : s.springs) {
    if (g.other_dof >= 0) span = std::max<Index>(span, std::abs(g.dof - g.other_dof));
  }
  return span;
}

}  // namespace

std::optional<PeriodicCut> find_periodic_cut(const GapStructure& s, Index period, Index margin) {
  const Index n = s.dofs();
  if (period <= 0 || margin <= 0 || n < 8 * period) return std::nullopt;
  const std::vector<LoadGroup> loads = s.load_groups();
  const SpringsByDof springs(s);
  // repeats(i): degree of freedom i carries what i - period carries.
  const auto repeats = [&](Index i) {
    if (i < period) return false;
    for (const SparseMatrix* A : {&s.mass, &s.damping, &s.stiffness}) {
      if (!shifted_column_matches(*A, i - period, period)) return false;
    }
    for (const LoadGroup& g : loads) {
      if (g.sin_part[i] != g.sin_part[i - period] || g.cos_part[i] != g.cos_part[i - period]) {
        return false;
      }
    }
    return springs.repeats(s, i, period);
  };
  const Index mid = n / 2;
  if (!repeats(mid)) return std::nullopt;
  Index run_first = mid, run_last = mid + 1;
  while (run_first - 1 >= period && repeats(run_first - 1)) --run_first;
  while (run_last < n && repeats(run_last)) ++run_last;
  PeriodicCut cut;
  cut.period = period;
  cut.margin = margin;
  cut.periodic_first = run_first - period;  // [a, b) repeats with the period
  cut.periodic_last = run_last;
  cut.cut = cut.periodic_first + margin;
  const Index room = cut.periodic_last - margin - cut.cut;
  cut.removed = room > 0 ? room / (2 * period) * (2 * period) : 0;
  // Worth it only when a quarter of the chain goes, and the couplings across the cut must not
  // reach over the whole removed stretch.
  const Index span = coupling_span(s);
  if (cut.removed < n / 4 || cut.removed <= span || margin <= span) return std::nullopt;
  cut.span = span;
  return cut;
}

GapStructure shorten(const GapStructure& s, const PeriodicCut& cut) {
  const Index c = cut.cut, D = cut.removed, n = s.dofs();
  // Where degree of freedom pair (i, j) of the long chain goes in the short one: kept before the
  // cut, moved D back after it, and a pair from the removed stretch to beyond it stands in for
  // the pair across the cut (the same content, one whole number of periods on). -1: left out.
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

AxisRepeat axis_repeat(const PeriodicCut& cut, Index units_before, Index units_per_period) {
  return {units_before, units_per_period, cut.removed / cut.period};
}

AxisRepeat spring_axis(const GapStructure& short_structure, const PeriodicCut& cut) {
  Index before = 0, period = 0;
  for (const GapSpring& g : short_structure.springs) {
    const Index p = first_end(g);
    if (p < cut.cut) ++before;
    if (p < cut.cut && p >= cut.cut - cut.period) ++period;
  }
  return axis_repeat(cut, before, period);
}

bool diagonal_mass(const GapStructure& s) {
  for (Index j = 0; j < s.mass.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(s.mass, j); it; ++it) {
      if (it.row() != j && it.value() != 0.0) return false;
    }
  }
  return true;
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

}  // namespace pwl::banded_detail
