#pragma once
// A linear structure with gap-activated springs and harmonic loads:
//
//     M x'' + C x' + K x = f(t) - W P,     P_j = k_j max(0, g_j),   g = W^T x - Δ.
//
// Column j of W is the direction in which spring j acts: s (e_a - e_b) for a spring between two
// degrees of freedom a and b (a clearance between neighbours), or s e_a for one tied to the ground;
// s = +1 closes the gap when the (relative) displacement grows, s = -1 when it shrinks. The spring
// pushes back only once the gap g_j is closed. A negative gap is a preload. The spring force is
// continuous in x; only its slope jumps at g_j = 0, which is what makes the structure
// piecewise-linear.
//
// M, C and K are stored sparse so that the same type carries a 5-mass study (dense enough) and a
// 10^5-mass chain (banded). The integrators pick the storage they need.
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl {

// One gap spring. The gap function is g = direction * (x[dof] - x[other_dof]) - gap, with
// x[-1] = 0 (ground); the force is stiffness * max(0, g).
struct GapSpring {
  int dof = 0;
  int other_dof = -1;      // -1: tied to the ground
  double direction = 1.0;  // +1 or -1
  double stiffness = 0.0;  // k_j >= 0
  double gap = 0.0;        // Δ_j; negative means preloaded
};

// A harmonic load amplitude * sin(omega * t + phase) on one degree of freedom. omega = 0 gives a
// constant load amplitude * sin(phase).
struct HarmonicLoad {
  int dof = 0;
  double amplitude = 0.0;
  double omega = 0.0;
  double phase = 0.0;
};

// Loads that share a frequency, summed: f(t) = sin_part * sin(omega t) + cos_part * cos(omega t).
// Integrators treat one group with one pair of exact load integrals.
struct LoadGroup {
  double omega = 0.0;
  Vector sin_part;
  Vector cos_part;
};

class GapStructure {
 public:
  SparseMatrix mass;       // M: symmetric positive definite
  SparseMatrix damping;    // C: symmetric positive semidefinite
  SparseMatrix stiffness;  // K: symmetric positive semidefinite (may be singular: free-free)
  std::vector<GapSpring> springs;
  std::vector<HarmonicLoad> loads;

  Index dofs() const { return mass.rows(); }
  Index spring_count() const { return static_cast<Index>(springs.size()); }

  // Ceres-style validity check: false with a message naming the field and the value.
  bool is_valid(std::string* why) const;
  // Throws InputError with that message.
  void validate() const;

  // W (dofs x springs), dense: column j is the direction of spring j.
  Matrix spring_directions() const;
  SparseMatrix spring_directions_sparse() const;
  Vector spring_gaps() const;         // Δ
  Vector spring_stiffnesses() const;  // k
  // g = W^T x - Δ
  Vector gap_functions(const Eigen::Ref<const Vector>& x) const;
  // P = k max(0, g): the spring forces, continuous in x.
  Vector spring_forces(const Eigen::Ref<const Vector>& x) const;
  // f(t)
  Vector load(double t) const;
  // The loads grouped by frequency (relative tolerance 1e-12 on omega).
  std::vector<LoadGroup> load_groups() const;
  // The smallest T > 0 with every load T-periodic. Throws InputError when there are no
  // time-varying loads or their frequencies are incommensurate (ratios not rational with
  // denominators up to max_denominator within rel_tol).
  double common_period(int max_denominator = 1000, double rel_tol = 1e-9) const;
  // Largest finite magnitude of any entry of M, C, K, used to scale tolerances.
  double scale() const;
};

// Convenience: a dense n x n matrix as sparse (zeros dropped).
SparseMatrix to_sparse(const Matrix& dense);

}  // namespace pwl
