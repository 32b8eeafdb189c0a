#pragma once
// Builders for the paper's chain (He, Gao & Zhong 2018, eqs 1-3 and 23-25): n masses in a line,
// mass i tied to mass i-1 by a spring k1 and a damper c (mass 1 to a fixed wall, the last mass
// free on its right), and a gap spring k2 on the right of every mass that pushes back once
// x_i exceeds its gap Δ_i.
#include <vector>

#include "pwl/model/gap_structure.hpp"

namespace pwl {

// L = tridiag(-1, 2, -1) with L[n-1][n-1] = 1: the fixed-free chain's Laplacian.
SparseMatrix fixed_free_laplacian(Index n);

// Physical units. Vectors of per-mass values may hold one value (used for every mass) or n.
struct ChainParameters {
  int masses = 1000;
  std::vector<double> mass{1.0};          // kg
  std::vector<double> k1{1.0};            // N/m, spring between mass i-1 and i
  std::vector<double> damping{0.2};       // N·s/m, damper between mass i-1 and i
  std::vector<double> k2{1.0};            // N/m, gap spring of each mass
  std::vector<double> gap{0.0};           // m, gap of each mass's spring
  std::vector<HarmonicLoad> loads;        // dof is 0-based
};
// Builds the chain. Throws InputError naming the field for wrong sizes or values.
GapStructure make_chain(const ChainParameters& p);

// The paper's section 4.2 chain: unit masses and springs, c = 0.2, Δ = 0, sin(3t) on the odd
// masses (1, 3, ..., 1-based) and -2 sin(5t) on the even ones.
ChainParameters paper_large_chain(int masses = 1000);

// The nondimensional form (eqs 23-25): x'' + ζ L x' + L x = -P + Q sin(θτ),
// P_i = α_i max(0, x_i - Δ̃_i). Time is τ = ω0 t; one forcing period is T = 2π/θ.
struct NondimensionalChain {
  int masses = 5;
  std::vector<double> alpha{2.0};  // k2/k1, per mass or one value
  double zeta = 0.2;               // c / sqrt(k1 m)
  std::vector<double> gap{0.0};    // Δ̃, per mass or one value
  double theta = 1.0;              // ω/ω0
  std::vector<double> amplitude{1.0, -1.0, 1.0, -1.0, 1.0};  // Q, per mass or one value
  double period() const;           // 2π/θ
};
GapStructure make_chain(const NondimensionalChain& p);

// The paper's 5-DOF cases by figure name: "4a", "4b", "5", "6" (SPEC.md §5). Throws InputError
// for another name.
NondimensionalChain paper_five_dof_case(const std::string& figure);

}  // namespace pwl
