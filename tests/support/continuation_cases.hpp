#pragma once
// Continuation cases shared by the matrix-free continuation tests: the paper's chain at any
// length, the motion settled from rest as a guess, one branch followed with a given solver, and
// the checks they share (the first period doubling, a switched period-2 branch's orbits).
#include <catch2/catch.hpp>
#include <cmath>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"

namespace pwl::test {

// The paper's chain of `masses` masses (α = 2, ζ = 0.2, Δ̃ = 0, Q alternating ±1) at θ.
inline NondimensionalChain paper_chain(int masses, double theta) {
  NondimensionalChain chain;
  chain.masses = masses;
  chain.alpha = {2.0};
  chain.zeta = 0.2;
  chain.gap = {0.0};
  chain.amplitude.clear();
  for (int i = 0; i < masses; ++i) chain.amplitude.push_back(i % 2 == 0 ? 1.0 : -1.0);
  chain.theta = theta;
  return chain;
}

// The state 200 forcing periods after rest (a guess for the period-1 orbit).
inline Vector settled_guess(const NondimensionalChain& chain, const MethodSettings& method,
                            int steps) {
  orbits::StroboscopicMap map(analysis::PointCase(chain), method, steps);
  return map.advance(Vector::Zero(2 * chain.masses), 200);
}

// The branch from `guess` with the options `o` and the shooting solver `solver` (dense: the
// monodromy at every point; krylov: matrix-free).
inline orbits::ContinuationResult follow(const NondimensionalChain& chain, const Vector& guess,
                                         orbits::ContinuationOptions o,
                                         orbits::ShootingSolver solver) {
  o.shooting.solver = solver;
  return orbits::continue_periodic_orbit(analysis::PointModel(chain), guess, o);
}

// The first period doubling located on branch 0 (the branch followed from the start), or nullptr.
inline const orbits::Bifurcation* first_doubling(const orbits::ContinuationResult& r) {
  for (const orbits::Bifurcation& b : r.bifurcations) {
    if (b.branch == 0 && b.type == orbits::BifurcationType::period_doubling) return &b;
  }
  return nullptr;
}

// The point of `branch` nearest θ (null when the branch has none).
inline const orbits::BranchPoint* nearest_point(const orbits::ContinuationResult& r, int branch,
                                                double theta) {
  const orbits::BranchPoint* best = nullptr;
  for (const orbits::BranchPoint& p : r.points) {
    if (p.branch != branch) continue;
    if (best == nullptr || std::abs(p.parameter - theta) < std::abs(best->parameter - theta)) {
      best = &p;
    }
  }
  return best;
}

// Checks that the points of `branch` are genuine period-2 orbits of the chain `at(θ)`: period 2,
// carried twice round by a fresh map (method, steps a period) back onto themselves to 1e-8, and,
// farther than `near` in θ from the doubling at `doubling`, not once round (by more than `apart`).
// Returns how many points it checked.
template <class ChainAt>
int check_period_two_branch(const orbits::ContinuationResult& r, int branch, double doubling,
                            ChainAt&& at, const MethodSettings& method, int steps, double near,
                            double apart) {
  int checked = 0;
  for (const orbits::BranchPoint& p : r.points) {
    if (p.branch != branch) continue;
    ++checked;
    CHECK(p.orbit.period == 2);
    orbits::StroboscopicMap map(analysis::PointCase(at(p.parameter)), method, steps);
    const Vector once = map.advance(p.orbit.state, 1);
    const Vector twice = map.advance(once, 1);
    CHECK((twice - p.orbit.state).lpNorm<Eigen::Infinity>() <= 1e-8);
    if (std::abs(p.parameter - doubling) > near) {
      CHECK((once - p.orbit.state).lpNorm<Eigen::Infinity>() > apart);
    }
  }
  return checked;
}

}  // namespace pwl::test
