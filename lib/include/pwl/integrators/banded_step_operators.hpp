#pragma once
// The constant operators of one precise-integration step as banded matrices: the same numbers
// as pim_step_operators.hpp (He, Gao & Zhong 2018, eqs 8-14 with the misprints fixed as in
// SPEC.md §3), up to the stated truncation, with work and storage linear in the number of
// degrees of freedom.
//
//     v̄_{k+1} = T v_k + Σ_ω (sin ωt_k · h_sin + cos ωt_k · h_cos) + Ψ P_k
//     v_{k+1} = v̄_{k+1} + Φ P_{k+1}
//     ν = (I - K2 W^T Φ_x) P_{k+1} + K2 (Δ - W^T x̄_{k+1}),  P ≥ 0, ν ≥ 0, P·ν = 0
//
// With G = [0; -M⁻¹W]: Φ = rising_load · (-M⁻¹W) and Ψ = falling_load · (-M⁻¹W), products of
// the banded load integrals of banded_exponential.hpp with the sparse spring directions, so
// they are banded too; so is the LCP matrix.
//
// The state is interleaved, [x_0, x_0', x_1, x_1', ...] (see banded_exponential.hpp). The springs
// are renumbered in the order of their position along the structure (by their lower degree of
// freedom), so that the LCP matrix is banded whatever order the structure lists them in;
// spring_order maps the new numbering to the structure's.
#include <vector>

#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/numerics/banded_matrix.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/pim_step_operators.hpp"

namespace pwl {

struct BandedStepOperators {
  double step = 0.0;                        // η
  BandedMatrix transition;                  // T, 2n x 2n (interleaved state)
  BandedMatrix force_now;                   // Ψ, 2n x m: multiplies P_k
  BandedMatrix force_next;                  // Φ, 2n x m: multiplies P_{k+1}
  std::vector<HarmonicResponse> harmonics;  // interleaved, one per load frequency
  BandedMatrix lcp_matrix;                  // I - K2 W^T Φ_x, m x m
  SparseMatrix gap_rows;                    // K2 W^T, m x n (springs in spring_order)
  Vector gaps;                              // Δ, m (spring_order)
  Vector stiffnesses;                       // k, m (spring_order)
  std::vector<Index> spring_order;          // banded spring j is the structure's spring_order[j]
  BandTruncation truncation;
};

// Builds the operators for a validated structure with a diagonal mass matrix and step η > 0.
// Throws InputError for a bad structure, step or options.
BandedStepOperators make_banded_step_operators(const GapStructure& structure, double step,
                                               const BandedExponentialOptions& options = {});

// The springs by position along the structure: ordered by their lower degree of freedom, then
// the higher one (ground = -1 counts as the same position), then their index.
std::vector<Index> springs_by_position(const GapStructure& structure);

}  // namespace pwl
