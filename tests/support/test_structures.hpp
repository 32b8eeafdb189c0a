#pragma once
// Structures and comparisons the tests of several rooms share: the single-mass oscillator whose
// motion is known in closed form, the chain with random cells, and the largest difference of two
// integrators' states.
#include <algorithm>
#include <random>

#include "pwl/integrators/integrator.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/model/gap_structure.hpp"

namespace pwl::test {

// One mass m on a spring k and a damper c to the wall, without gap springs or loads: the caller
// adds those it needs.
inline GapStructure single_mass(double m, double c, double k) {
  GapStructure s;
  s.mass = to_sparse(Matrix::Constant(1, 1, m));
  s.damping = to_sparse(Matrix::Constant(1, 1, c));
  s.stiffness = to_sparse(Matrix::Constant(1, 1, k));
  return s;
}

// A spring of stiffness k between degrees of freedom i and j, added to the stiffness matrix K.
inline void add_spring(Matrix& K, Index i, Index j, double k) {
  K(i, i) += k;
  K(j, j) += k;
  K(i, j) -= k;
  K(j, i) -= k;
}

// The paper's section 4.2 chain with every cell drawn at random (seeded): masses and springs k1 in
// [0.5, 2], dampers in damping_scale · [0.5, 2], and, when vary_gap_springs, the gap springs k2
// in [0.5, 2] too. Cells that differ make a structure without a period, so that nothing can be
// shared between rows of a banded operator.
inline ChainParameters varying_chain(int n, unsigned seed, double damping_scale,
                                     bool vary_gap_springs) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  ChainParameters p = paper_large_chain(n);
  p.mass.clear();
  p.k1.clear();
  p.damping.clear();
  if (vary_gap_springs) p.k2.clear();
  for (int i = 0; i < n; ++i) {
    p.mass.push_back(u(rng));
    p.k1.push_back(u(rng));
    p.damping.push_back(damping_scale * u(rng));
    if (vary_gap_springs) p.k2.push_back(u(rng));
  }
  return p;
}

// The largest difference of two integrators' states, over every x and x'.
inline double largest_difference(const Integrator& a, const Integrator& b) {
  return std::max((a.position() - b.position()).cwiseAbs().maxCoeff(),
                  (a.velocity() - b.velocity()).cwiseAbs().maxCoeff());
}

}  // namespace pwl::test
