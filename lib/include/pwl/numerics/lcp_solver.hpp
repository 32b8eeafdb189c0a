#pragma once
// Linear complementarity problems: find z with
//
//     w = M z + q,   z >= 0,   w >= 0,   z^T w = 0.
//
// In a precise-integration step, z is the vector of gap-spring forces at the end of the step and w
// the complementary slack ν of the parametric variational principle. The step's matrix M stays the
// same for as long as the step size does, so a solver is told M once (set_matrix) and then solves
// for many right-hand sides q, warm-started from the previous solution: from one step to the next
// almost every spring keeps its state.
//
// When M is a P-matrix (all principal minors positive) the LCP has exactly one solution for every
// q (Cottle, Pang & Stone, The Linear Complementarity Problem, 1992, Thm 3.3.7). The step's matrix
// is I + O(η²) and is a P-matrix for any reasonable step; solvers report anything else as an
// LcpError instead of looping.
#include <memory>
#include <string>

#include "pwl/types.hpp"

namespace pwl {

// The LCP algorithms pwl ships. Names ("block-pivoting", "lemke") are for the command line and
// scene files only (lcp_algorithm_name, parse_lcp_algorithm).
enum class LcpAlgorithm {
  block_pivoting,  // Júdice & Pires 1994, warm-started; the default
  lemke,           // Lemke 1965, the paper's choice
};

// "block-pivoting" or "lemke".
std::string lcp_algorithm_name(LcpAlgorithm algorithm);
// The inverse. Throws InputError naming the value and the accepted names otherwise.
LcpAlgorithm parse_lcp_algorithm(const std::string& name);

struct LcpResult {
  int pivots = 0;  // principal pivots (block pivoting) or complementary pivots (Lemke)
};

class LcpSolver {
 public:
  virtual ~LcpSolver() = default;
  virtual std::string name() const = 0;
  virtual LcpAlgorithm algorithm() const = 0;
  // Tell the solver the matrix M (square, finite). It may factorise or cache here.
  virtual void set_matrix(const Matrix& M) = 0;
  // Solve for q. On entry z holds a warm start (its positive entries are the guessed active
  // set; zeros are fine); on exit z and w solve the LCP to within a tolerance relative to the
  // size of q. Throws LcpError when it cannot.
  virtual LcpResult solve(const Eigen::Ref<const Vector>& q, Eigen::Ref<Vector> z,
                          Eigen::Ref<Vector> w) = 0;
};

// Lemke's complementary pivoting method with the covering vector e = (1, ..., 1) and lexicographic
// minimum-ratio tie breaking, which cannot cycle (Lemke 1965; Cottle, Pang & Stone 1992, §4.4).
// The paper's choice. Ray termination is reported as an LcpError.
std::unique_ptr<LcpSolver> make_lemke_solver();

// Block principal pivoting (Júdice & Pires 1994) warm-started from the previous active set, with
// Murty's single principal pivoting as the fall-back that guarantees termination on P-matrices
// (Murty 1974). For small problems the inverse of each principal block M_AA it meets is cached,
// so a step whose active set was seen before costs one small matrix-vector product.
std::unique_ptr<LcpSolver> make_block_pivoting_solver();

// Either algorithm.
std::unique_ptr<LcpSolver> make_lcp_solver(LcpAlgorithm algorithm);
// Both by name: "lemke" or "block-pivoting". Throws InputError for anything else.
std::unique_ptr<LcpSolver> make_lcp_solver(const std::string& name);

// Whether M is a P-matrix. Exact (every principal minor) for size <= 12; for larger matrices a
// sufficient test (strict diagonal dominance with a positive diagonal, or a positive-definite
// symmetric part). Returns false and says why when the test fails.
bool is_p_matrix(const Matrix& M, std::string* why = nullptr);

// Largest violation of the LCP conditions by (z, w): max of -z, -w, |w - Mz - q| and |z_i w_i|,
// for tests and sanity checks.
double lcp_residual(const Matrix& M, const Vector& q, const Vector& z, const Vector& w);

}  // namespace pwl
