#pragma once
// Whether the Floquet multipliers near the unit circle moved less than half the band's margin
// between the two ends of a continuation step, for the band check of continuation.cpp
// (ArnoldiOptions::margin). Private to the orbits room.
//
// Each multiplier within half the margin of the circle at one end (||μ| − 1| <= margin / 2) must
// have a partner of its own at the other end within half the margin of it, one to one: a
// matching of those multipliers into the other end's in the bipartite graph whose edges join
// multipliers at most margin / 2 apart, found by augmenting paths (Kuhn's method; H. W. Kuhn,
// Naval Res. Logist. Q. 2 (1955) 83-97). Both ends are taken in turn, so the answer does not
// depend on which end is which. One to one, so that in a crowd (the long waves of a chain, spaced
// closer than the margin) two multipliers are not both explained by one that stayed while the
// other moved away. A multiplier that moved less than half the margin is, at the other end,
// within the band |μ| > 1 − margin that Arnoldi reports whole, so its partner is there to be
// found.
#include <cmath>
#include <complex>
#include <functional>
#include <utility>
#include <vector>

namespace pwl::orbits::detail {

inline bool band_stayed(const std::vector<std::complex<double>>& a,
                        const std::vector<std::complex<double>>& b, double margin) {
  const double reach = 0.5 * margin;
  for (const auto& [from, to] : {std::pair{&a, &b}, std::pair{&b, &a}}) {
    std::vector<std::vector<std::size_t>> edges;  // of each multiplier near the circle
    for (const auto& m : *from) {
      // A NaN modulus counts as near, and has no edge: the step is not trusted.
      if (std::abs(std::abs(m) - 1.0) > reach) continue;
      edges.emplace_back();
      for (std::size_t j = 0; j < to->size(); ++j) {
        if (std::abs(m - (*to)[j]) <= reach) edges.back().push_back(j);
      }
      if (edges.back().empty()) return false;
    }
    std::vector<long> owner(to->size(), -1);  // the near multiplier each partner is matched to
    std::vector<bool> seen;
    const std::function<bool(std::size_t)> augment = [&](std::size_t i) {
      for (const std::size_t j : edges[i]) {
        if (seen[j]) continue;
        seen[j] = true;
        if (owner[j] < 0 || augment(static_cast<std::size_t>(owner[j]))) {
          owner[j] = static_cast<long>(i);
          return true;
        }
      }
      return false;
    };
    for (std::size_t i = 0; i < edges.size(); ++i) {
      seen.assign(to->size(), false);
      if (!augment(i)) return false;
    }
  }
  return true;
}

}  // namespace pwl::orbits::detail
