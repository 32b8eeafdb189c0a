// The step-selection rule of He, Gao & Zhong, Appl. Math. Mech. 39(7) (2018) 737-749, §2: run
// the 2^N algorithm of the precise integration method (Zhong & Williams, Proc. IMechE C 208
// (1994) 427-430) on a substructure and stop doubling when energy leaves q cells.
#include "pwl/integrators/banded_step_rule.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <unordered_map>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/numerics/substructure_exponential.hpp"

namespace pwl {

bool BandedStepRuleOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!std::isfinite(wished_step) || wished_step <= 0.0) {
    *why = fmt::format("wished_step = {} must be positive and finite", wished_step);
    return false;
  }
  if (band < 1) {
    *why = fmt::format("band = {} must be at least 1", band);
    return false;
  }
  if (!(tolerance > 0.0 && tolerance < 1.0)) {
    *why = fmt::format("tolerance = {} must be in (0, 1)", tolerance);
    return false;
  }
  if (guard < 1) {
    *why = fmt::format("guard = {} must be at least 1 (the watched entries lie beyond q)", guard);
    return false;
  }
  return exponential.is_valid(why);
}

namespace {

// Largest ratio, over the four blocks of T's rows x_i and x_i' (local row li of a w-dof
// substructure whose first dof is `first`), of the entries more than q from dof i to the block
// row's sum.
double leaked_ratio(const Matrix& T, Index w, Index first, Index i, Index q) {
  const Index li = i - first;
  double worst = 0.0;
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      double total = 0.0, beyond = 0.0;
      for (Index lj = 0; lj < w; ++lj) {
        const double v = std::abs(T(a * w + li, b * w + lj));
        total += v;
        if (std::abs(first + lj - i) > q) beyond += v;
      }
      if (total > 0.0) worst = std::max(worst, beyond / total);
    }
  }
  return worst;
}

// The ratio after each doubling d = 0..N for one substructure and row.
std::vector<double> watch(const GapStructure& s, Index first, Index last, Index i,
                          const BandedStepRuleOptions& o) {
  const Matrix H = substructure_state_matrix(s, first, last);
  const Index w = last - first;
  const int N = o.exponential.doublings;
  const double tau0 = std::ldexp(o.wished_step, -N);
  // The Taylor increment T_a = exp(Hτ0) - I, then T_a <- 2 T_a + T_a T_a (precise_exponential.hpp).
  Matrix Ta = Matrix::Zero(2 * w, 2 * w);
  Matrix power = Matrix::Identity(2 * w, 2 * w);
  for (int k = 1; k <= o.exponential.taylor_order; ++k) {
    power = power * H * (tau0 / k);
    Ta += power;
  }
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(N + 1));
  Matrix T;
  for (int d = 0;; ++d) {
    T = Ta;
    T.diagonal().array() += 1.0;
    out.push_back(leaked_ratio(T, w, first, i, o.band));
    if (d == N) break;
    Ta = 2.0 * Ta + Ta * Ta;
  }
  return out;
}

struct WatchKey {
  SubstructureKey window;
  Index row;
  bool operator==(const WatchKey& o) const { return row == o.row && window == o.window; }
};
struct WatchKeyHasher {
  std::size_t operator()(const WatchKey& k) const {
    return k.window.hash() ^ (static_cast<std::size_t>(k.row) * 0x9e3779b97f4a7c15ULL);
  }
};

}  // namespace

BandedStepChoice select_banded_step(const GapStructure& structure,
                                    const BandedStepRuleOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError("step rule options: " + why);
  structure.validate();
  for (Index j = 0; j < structure.mass.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(structure.mass, j); it; ++it) {
      if (it.row() != j && it.value() != 0.0) {
        throw InputError(fmt::format("mass[{},{}] = {}: the step rule needs a diagonal (lumped) "
                                     "mass matrix",
                                     it.row(), j, it.value()));
      }
    }
  }
  const Index n = structure.dofs();
  const Index R = options.band + options.guard;
  // One substructure per row, reaching R beyond it (clamped at the ends); rows whose
  // substructure and position in it repeat are watched once.
  struct Item {
    Index first, last, row;
  };
  std::unordered_map<WatchKey, std::size_t, WatchKeyHasher> seen;
  std::vector<Item> items;
  for (Index i = 0; i < n; ++i) {
    const Index first = std::max<Index>(0, i - R), last = std::min(n, i + R + 1);
    WatchKey key{SubstructureKey(structure, first, last), i - first};
    if (seen.try_emplace(std::move(key), items.size()).second) items.push_back({first, last, i});
  }
  const int N = options.exponential.doublings;
  std::vector<std::vector<double>> results(items.size());
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic) if (items.size() > 1)
  for (std::size_t k = 0; k < items.size(); ++k) {
    try {
      results[k] = watch(structure, items[k].first, items[k].last, items[k].row, options);
    } catch (...) {
#pragma omp critical
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);

  BandedStepChoice c;
  c.wished_step = options.wished_step;
  c.start_step = std::ldexp(options.wished_step, -N);
  c.band = options.band;
  c.doublings = N;
  c.substructures = static_cast<Index>(items.size());
  c.leaked.assign(static_cast<std::size_t>(N + 1), 0.0);
  for (const auto& r : results) {
    for (std::size_t d = 0; d < r.size(); ++d) c.leaked[d] = std::max(c.leaked[d], r[d]);
  }
  for (int d = 0; d <= N; ++d) {
    if (c.leaked[static_cast<std::size_t>(d)] > options.tolerance) {
      c.exceeded_after = d;
      break;
    }
  }
  if (c.exceeded_after == 0) {
    throw InputError(fmt::format(
        "band = {}: energy travels more than {} degrees of freedom even within τ0 = {} (leaked "
        "ratio {:.3g} > tolerance {}); use a larger band",
        options.band, options.band, c.start_step, c.leaked[0], options.tolerance));
  }
  const int at = c.exceeded_after < 0 ? N : c.exceeded_after - 1;
  c.step = c.exceeded_after < 0 ? options.wished_step : std::ldexp(c.start_step, at);
  c.leaked_at_step = c.leaked[static_cast<std::size_t>(at)];
  return c;
}

}  // namespace pwl
