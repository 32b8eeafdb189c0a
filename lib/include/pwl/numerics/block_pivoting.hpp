#pragma once
// Block principal pivoting for the LCP w = M z + q, z >= 0, w >= 0, z^T w = 0: the pivoting rule
// once, for every form in which pwl solves the step's LCP. The forms differ only in how they solve
// the principal system of an active set, and that is their policy:
//
//  - dense, with the inverse of each principal block cached by active set (lcp_solver.cpp), or
//    one LU factorisation kept for the last set (large problems, same file);
//  - banded, by Jacobi sweeps or a band LU of the active set (banded_lcp_solver.cpp);
//  - fixed-size and inline, inside the 5-DOF stepper (precise_propagator.hpp) and the switching
//    PIM's smooth step (switching_pim.cpp), with a transform per active set.
//
// The method
//   J. J. Júdice, F. M. Pires, "A block principal pivoting algorithm for large-scale strictly
//     monotone linear complementarity problems", Computers & Operations Research 21 (1994)
//     587-596: every infeasible index switches at once while their number decreases, with a
//     counter of non-improving iterations.
//   K. G. Murty, "Note on a Bard-type scheme for solving the complementarity problem", Opsearch
//     11 (1974) 123-130: single principal pivoting on the largest infeasible index, finite for
//     P-matrices; the fall-back of the block method.
//
// For an active set A (z_i basic for i in A, w_i basic otherwise) the complementary basic vector
// x (x_A = z_A, x_F = w_F) is
//     z_A = -M_AA⁻¹ q_A,    w_F = q_F + M_FA z_A,
// and A solves the LCP iff x >= 0. The infeasible indices H = {i : x_i < 0} are switched all at
// once while that reduces |H| (or for up to kBlockTries non-improving iterations); after that
// only the largest index in H is switched (Murty), until |H| drops below its best value again.
// For a P-matrix every Murty run is finite and |H|'s best value only decreases, so the method
// terminates.
//
// Header-only and free of virtual calls, so that the fixed-size steppers inline all of it.
#include <algorithm>
#include <bit>
#include <cstdint>

#include <Eigen/LU>

#include "pwl/types.hpp"

namespace pwl::block_pivoting {

// Entries of the complementary basic vector down to -kFeasibilityTolerance |q|_inf count as
// non-negative (and are clamped to 0 on output). Relative to q so that the answer does not depend
// on units.
inline constexpr double kFeasibilityTolerance = 1e-11;
// Non-improving block iterations allowed before Murty's rule (Júdice & Pires).
inline constexpr int kBlockTries = 3;

// The feasibility tolerances of one right-hand side: w for the slacks, z for the forces. z entries
// scale like q / M, so tol_z = tol_w / max |M_ij| keeps M z within tol_w.
struct Tolerances {
  double w = 0.0;
  double z = 0.0;
};

inline Tolerances tolerances(double q_max, double m_scale) {
  Tolerances t;
  t.w = kFeasibilityTolerance * q_max;
  t.z = t.w / m_scale;
  return t;
}

// Whether z = 0 solves the LCP (every q_i >= -tol_w): the first test of every form.
inline bool zero_solves(double q_min, const Tolerances& tol) { return q_min >= -tol.w; }

// The pivoting loop. A policy holds the current active set and provides
//
//   int evaluate(long iteration);          // solve the principal system of the active set, form
//                                          // x, and return the number of infeasible entries
//   void exchange_infeasible();            // switch every infeasible index (block pivot)
//   void exchange_largest_infeasible();    // switch the largest infeasible index only (Murty)
//   LcpError iteration_error(long iteration) const;  // thrown at max_iterations
//
// Returns the number of principal pivots; on return the policy's active set solves the LCP and
// its last evaluation is the complementary basic vector. `size` is the LCP's size.
template <class Policy>
int solve(Policy& policy, int size, long max_iterations) {
  int pivots = 0;
  int best_count = size + 1;
  int tries = kBlockTries;
  for (long iteration = 0;; ++iteration) {
    if (iteration >= max_iterations) throw policy.iteration_error(iteration);
    const int count = policy.evaluate(iteration);
    if (count == 0) return pivots;
    if (count < best_count || tries > 0) {
      if (count < best_count) {
        best_count = count;
        tries = kBlockTries;
      } else {
        --tries;
      }
      policy.exchange_infeasible();
      pivots += count;
    } else {
      policy.exchange_largest_infeasible();
      pivots += 1;
    }
  }
}

// An active set of at most 32 indices as a bitmask (bit i: z_i basic), with the infeasible
// indices of its last evaluation: the exchanges of the policies whose sets are small.
struct MaskedActiveSet {
  std::uint32_t mask = 0;
  std::uint32_t infeasible = 0;

  // Marks the entries of x (the complementary basic vector of `mask`, n entries) below their
  // tolerance and returns how many there are.
  template <class X>
  int mark_infeasible(const X& x, int n, const Tolerances& tol) {
    infeasible = 0;
    for (int i = 0; i < n; ++i) {
      const double t = (mask >> i & 1u) ? tol.z : tol.w;
      if (x[i] < -t) infeasible |= 1u << i;
    }
    return infeasible == 0 ? 0 : std::popcount(infeasible);
  }
  void exchange_infeasible() { mask ^= infeasible; }
  void exchange_largest_infeasible() { mask ^= 1u << (31 - std::countl_zero(infeasible)); }
};

// z and w from the complementary basic vector x of a solving active set: z_i = max(x_i, 0) on the
// active set (`active(i)`), w_i = max(x_i, 0) elsewhere, zeros in the other.
template <class X, class Active, class Z, class W>
void split_basic_vector(const X& x, Index n, const Active& active, Z& z, W& w) {
  for (Index i = 0; i < n; ++i) {
    const double v = std::max(x[i], 0.0);
    const bool basic_z = active(i);
    z[i] = basic_z ? v : 0.0;
    w[i] = basic_z ? 0.0 : v;
  }
}

// The transform T_A of the active set `mask` of the n x n matrix M, x = T_A q with
// z_A = -M_AA⁻¹ q_A and w_F = q_F - M_FA M_AA⁻¹ q_A, by a full-pivoting LU of M_AA: for the
// fixed-size steppers, which compute it once per active set met and keep it. Returns false when
// M_AA is singular (M is not a P-matrix); t is then filled as if M_AA⁻¹ were the identity and
// must not be used.
template <class Transform>
bool active_set_transform(const Matrix& M, Index n, std::uint64_t mask, Transform& t) {
  Index ia[64];
  Index k = 0;
  for (Index i = 0; i < n; ++i)
    if (mask >> i & 1u) ia[k++] = i;
  Matrix block(k, k);
  for (Index a = 0; a < k; ++a)
    for (Index b = 0; b < k; ++b) block(a, b) = M(ia[a], ia[b]);
  Matrix inverse = Matrix::Identity(k, k);
  bool invertible = true;
  if (k > 0) {
    const Eigen::FullPivLU<Matrix> lu(block);
    if (lu.isInvertible()) {
      inverse = lu.inverse();
    } else {
      invertible = false;
    }
  }
  t.setZero(n, n);
  for (Index a = 0; a < k; ++a)
    for (Index b = 0; b < k; ++b) t(ia[a], ia[b]) = -inverse(a, b);
  for (Index i = 0; i < n; ++i) {
    if (mask >> i & 1u) continue;
    t(i, i) = 1.0;
    for (Index b = 0; b < k; ++b) {
      double s = 0.0;
      for (Index a = 0; a < k; ++a) s += M(i, ia[a]) * inverse(a, b);
      t(i, ia[b]) = -s;
    }
  }
  return invertible;
}

}  // namespace pwl::block_pivoting
