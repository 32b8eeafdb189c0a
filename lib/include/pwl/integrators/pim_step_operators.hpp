#pragma once
// The constant operators of one precise-integration step of a GapStructure (He, Gao & Zhong 2018,
// eqs 8-14, with the misprints fixed as in SPEC.md §3).
//
// With state v = [x; x'], v' = H v + F(t), H = [[0, I], [-M⁻¹K, -M⁻¹C]], the spring forces taken
// linear inside the step, P(t_k + s) = (1 - s/η) P_k + (s/η) P_{k+1}, and harmonic loads
// integrated exactly, one step is
//
//     v̄_{k+1} = T v_k + Σ_ω (sin ωt_k · h_sin + cos ωt_k · h_cos) + Ψ P_k
//     v_{k+1} = v̄_{k+1} + Φ P_{k+1}
//
// and the spring forces at the end of the step solve the LCP (the parametric variational
// principle: P - K2 g - ν = 0, P ≥ 0, ν ≥ 0, P·ν = 0 with g = W^T x - Δ)
//
//     ν = (I - K2 W^T Φ_x) P_{k+1} + K2 (Δ - W^T x̄_{k+1}).
//
// With G = [0; -M⁻¹W] (the spring directions in state space): Φ = (Γ0 - Γ1/η) G, Ψ = (Γ1/η) G,
// using the inverse-free integrals of precise_exponential.hpp.
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

// One frequency's exact response over a step: add sin(ωt_k) sin_response + cos(ωt_k) cos_response.
struct HarmonicResponse {
  double omega = 0.0;
  Vector sin_response;  // 2n
  Vector cos_response;  // 2n
};

struct PimStepOperators {
  double step = 0.0;                        // η
  Matrix transition;                        // T = exp(Hη), 2n x 2n
  Matrix force_now;                         // Ψ, 2n x m: multiplies P_k
  Matrix force_next;                        // Φ, 2n x m: multiplies P_{k+1}
  std::vector<HarmonicResponse> harmonics;  // one per load frequency
  Matrix lcp_matrix;                        // I - K2 W^T Φ_x, m x m
  Matrix directions;                        // W, n x m
  Vector gaps;                              // Δ, m
  Vector stiffnesses;                       // k, m
};

// Builds the operators for a validated structure and step η > 0. Throws InputError for a bad
// structure or step.
PimStepOperators make_pim_step_operators(const GapStructure& structure, double step,
                                         const PreciseExponentialOptions& options = {});

// H = [[0, I], [-M⁻¹K, -M⁻¹C]] as a dense matrix (for small and moderate n).
Matrix state_matrix(const GapStructure& structure);

}  // namespace pwl
