#pragma once
// Whether the Floquet multipliers near the unit circle moved less than half the band's margin
// between the two ends of a continuation step, for the band check of continuation.cpp
// (ContinuationOptions::band), and the band the reported multipliers cover. Private to the orbits
// room.
//
// Each multiplier within half the margin of the circle at one end (||μ| − 1| <= margin / 2) must
// have a partner of its own at the other end, one to one: a matching of those multipliers into
// the other end's in the bipartite graph whose edges join a multiplier to those that are its
// partners, found by augmenting paths (Kuhn's method; H. W. Kuhn, Naval Res. Logist. Q. 2 (1955)
// 83-97). Both ends are taken in turn, so the answer does not depend on which end is which. One
// to one, so that in a crowd (the long waves of a chain, spaced closer than the margin) two
// multipliers are not both explained by one that stayed while the other moved away.
//
// A partner is within half the margin of it in the plane, or within half the margin of it in
// modulus having turned by at most kBandTurn radians. The band watches the moduli: a multiplier
// that turns round the origin at a constant modulus neither leaves nor enters the disc, and a
// long chain's long waves, just inside the circle, turn by ω dT as the period T changes with the
// forcing frequency (at 1000 masses, about 3e-4 rad a step of 0.005 in θ, far more than a band of
// 1e-5 that the leading multipliers alone can watch there) while their moduli hardly move. The
// turn is bounded all the same, so that one pair that goes out while another comes in elsewhere
// on the circle (a stable window inside one step) still finds no partner. A multiplier that
// moved less than half the margin in modulus is, at the other end, within the band
// |μ| > 1 − margin whose every multiplier the caller passes, so its partner is there to be found.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "pwl/orbits/floquet_multipliers.hpp"

namespace pwl::orbits::detail {

// The band below the unit circle whose every multiplier is among those reported, which the band
// check is narrowed to: all of it (1) where they are all 2n of them, else down to the smallest
// modulus reported (the leading ones, found by modulus; with ArnoldiOptions::margin, at least that
// margin where the band was covered); 0 with none, negative with all of them outside the circle.
inline double watched_band(const FloquetMultipliers& mu) {
  if (mu.complete) return 1.0;
  if (mu.values.empty()) return 0.0;
  double smallest = std::abs(mu.values.front());
  for (const auto& m : mu.values) smallest = std::min(smallest, std::abs(m));
  return 1.0 - smallest;
}

// The turn a partner may have made at nearly the same modulus (radians, about 1.1 degrees).
inline constexpr double kBandTurn = 0.02;

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
        const std::complex<double> p = (*to)[j];
        const bool partner = std::abs(m - p) <= reach ||
                             (std::abs(std::abs(m) - std::abs(p)) <= reach &&
                              std::abs(std::arg(m * std::conj(p))) <= kBandTurn);
        if (partner) edges.back().push_back(j);
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
