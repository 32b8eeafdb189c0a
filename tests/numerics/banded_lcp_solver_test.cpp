// The banded LCP solver against the dense solvers of lcp_solver.hpp (block pivoting and Lemke)
// on banded P-matrices of both kinds it treats differently: diagonally dominant (Jacobi sweeps on
// the active set) and not (band LU of the active set).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <random>

#include "pwl/numerics/banded_lcp_solver.hpp"
#include "pwl/integrators/banded_step_operators.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"

using namespace pwl;

namespace {

Matrix random_band(Index n, Index b, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix E = Matrix::Zero(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index j = std::max<Index>(0, i - b); j <= std::min(n - 1, i + b); ++j) E(i, j) = u(rng);
  return E;
}

// Strictly diagonally dominant with ratio `ratio`.
Matrix dominant(Index n, Index b, double ratio, std::mt19937& rng) {
  Matrix M = random_band(n, b, rng);
  for (Index i = 0; i < n; ++i) {
    M(i, i) = 0.0;
    M(i, i) = M.row(i).cwiseAbs().sum() / ratio + 1e-3;
  }
  return M;
}

// Positive definite symmetric part (a P-matrix) without diagonal dominance: B^T B + 0.05 I plus a
// skew-symmetric band.
Matrix definite(Index n, Index b, std::mt19937& rng) {
  const Matrix B = random_band(n, b, rng);
  const Matrix K = random_band(n, b, rng);
  return B.transpose() * B + 0.05 * Matrix::Identity(n, n) + 0.5 * (K - K.transpose());
}

Vector random_q(Index n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector q(n);
  for (Index i = 0; i < n; ++i) q[i] = u(rng);
  return q;
}

struct Solved {
  Vector z, w;
};

Solved solve(LcpSolver& s, const Vector& q, const Vector& warm) {
  Solved r{warm, Vector::Zero(q.size())};
  s.solve(q, r.z, r.w);
  return r;
}

}  // namespace

TEST_CASE("Banded LCP solutions equal the dense solvers' on banded P-matrices", "[banded][lcp]") {
  std::mt19937 rng(42);
  const Index n = 60;
  for (int kind = 0; kind < 2; ++kind) {
    for (Index b : {1, 3, 6}) {
      const Matrix M = kind == 0 ? dominant(n, b, 0.4, rng) : definite(n, b, rng);
      BandedLcpSolver banded;
      banded.set_matrix(BandedMatrix::from_dense_nonzeros(M));
      auto dense = make_block_pivoting_solver();
      dense->set_matrix(M);
      auto lemke = make_lemke_solver();
      lemke->set_matrix(M);
      INFO(std::string(kind == 0 ? "dominant" : "definite") << ", bandwidth " << b << ", dominance "
                                                 << banded.dominance());
      CHECK(banded.iterates() == (kind == 0));
      CHECK(is_p_matrix(BandedMatrix::from_dense_nonzeros(M)));
      for (int trial = 0; trial < 5; ++trial) {
        const Vector q = random_q(n, rng);
        const Solved a = solve(banded, q, Vector::Zero(n));
        const Solved d = solve(*dense, q, Vector::Zero(n));
        const Solved l = solve(*lemke, q, Vector::Zero(n));
        CHECK(lcp_residual(M, q, a.z, a.w) <= 1e-12);
        CHECK((a.z - d.z).cwiseAbs().maxCoeff() <= 1e-11 * (1 + d.z.cwiseAbs().maxCoeff()));
        CHECK((a.z - l.z).cwiseAbs().maxCoeff() <= 1e-10 * (1 + l.z.cwiseAbs().maxCoeff()));
        CHECK(a.z.minCoeff() >= 0.0);
        CHECK(a.w.minCoeff() >= 0.0);
      }
      if (kind == 0) {
        CHECK(banded.sweeps() > 0);
        CHECK(banded.factorized_rows() == 0);
      } else {
        CHECK(banded.factorized_rows() > 0);
      }
    }
  }
}

TEST_CASE("Warm starts from the previous solution take few pivots", "[banded][lcp]") {
  std::mt19937 rng(7);
  const Index n = 80;
  for (int kind = 0; kind < 2; ++kind) {
    const Matrix M = kind == 0 ? dominant(n, 4, 0.2, rng) : definite(n, 3, rng);
    BandedLcpSolver banded;
    banded.set_matrix(M);  // the dense interface keeps the band of the non-zeros
    auto dense = make_block_pivoting_solver();
    dense->set_matrix(M);
    // A second solver on the stepper's path: in place, from its own last active set.
    BandedLcpSolver stepper;
    stepper.set_matrix(M);
    const Vector q0 = random_q(n, rng), dq = random_q(n, rng);
    Vector z = Vector::Zero(n), w = Vector::Zero(n), zs = Vector::Zero(n);
    stepper.reset_active_set(zs);
    long warm_pivots = 0, cold_pivots = 0, stepper_pivots = 0;
    for (int k = 0; k < 40; ++k) {
      const Vector q = q0 + 0.02 * k * dq;
      warm_pivots += banded.solve(q, z, w).pivots;  // z holds the previous solution
      Vector zc = Vector::Zero(n), wc(n);
      cold_pivots += banded.solve(q, zc, wc).pivots;
      stepper_pivots += stepper.solve_forces(q, zs).pivots;
      const Solved d = solve(*dense, q, Vector::Zero(n));
      INFO("kind " << kind << ", k " << k);
      CHECK((z - d.z).cwiseAbs().maxCoeff() <= 1e-11 * (1 + d.z.cwiseAbs().maxCoeff()));
      CHECK((zc - d.z).cwiseAbs().maxCoeff() <= 1e-11 * (1 + d.z.cwiseAbs().maxCoeff()));
      CHECK((zs - d.z).cwiseAbs().maxCoeff() <= 1e-11 * (1 + d.z.cwiseAbs().maxCoeff()));
      std::vector<int> positive;
      for (Index i = 0; i < n; ++i)
        if (zs[i] > 0.0) positive.push_back(static_cast<int>(i));
      for (int i : positive) CHECK(std::find(stepper.active_set().begin(), stepper.active_set().end(), i) != stepper.active_set().end());
    }
    CHECK(warm_pivots * 4 < cold_pivots);
    CHECK(stepper_pivots == warm_pivots);
  }
}

TEST_CASE("The stepper's LCP finds every negative slack whatever the band's shape",
          "[banded][lcp]") {
  // solve_forces forms only the slacks that can be negative: rows j - upper .. j + lower of
  // each active j, and the q_i < 0 elsewhere. Bands with lower != upper (one of them 0),
  // contacts at both ends, and a contact that starts far from any other after the first solve,
  // on both of the solver's paths (sweeps and band LU), against the dense solver.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Index n = 40;
  for (auto [lower, upper] : std::vector<std::array<Index, 2>>{{4, 0}, {0, 4}, {1, 5}, {5, 1}}) {
    for (int path = 0; path < 2; ++path) {
      Matrix M = Matrix::Zero(n, n);
      for (Index i = 0; i < n; ++i) {
        for (Index j = std::max<Index>(0, i - lower); j <= std::min(n - 1, i + upper); ++j) {
          M(i, j) = i == j ? 0.0 : u(rng);
          // A strong push at the band's far edges, so that a contact pulls the slacks of the
          // rows farthest from it below zero.
          if (i != j && (j == i - lower || j == i + upper)) M(i, j) = -2.0;
        }
        M(i, i) = M.row(i).cwiseAbs().sum() / 0.4 + 1.0;
      }
      BandedLcpOptions options;
      if (path == 1) options.dominance_limit = 0.0;  // factorise
      BandedLcpSolver stepper(options);
      stepper.set_matrix(BandedMatrix::from_dense_nonzeros(M));
      REQUIRE(stepper.iterates() == (path == 0));
      auto dense = make_block_pivoting_solver();
      dense->set_matrix(M);
      Vector z = Vector::Zero(n);
      stepper.reset_active_set(z);
      for (int k = 0; k < 60; ++k) {
        Vector q(n);
        for (Index i = 0; i < n; ++i) q[i] = 0.15 + 0.1 * std::sin(0.3 * k + static_cast<double>(i));
        if (k % 20 < 12) q[0] = -1.0;                // the first spring, on and off
        if (k >= 10 && k < 40) q[n - 1] = -0.8;      // the last
        if (k >= 25) q[20] = -0.5 - 0.01 * k;        // alone, in the middle, from step 25
        if (k >= 45) q[8] = -0.3;                    // another, nearer the first
        stepper.solve_forces(q, z);
        const Solved d = solve(*dense, q, Vector::Zero(n));
        const Vector w = q + M * z;
        INFO("lower " << lower << ", upper " << upper << ", path " << path << ", k " << k);
        CHECK((z - d.z).cwiseAbs().maxCoeff() <= 1e-12 * (1 + d.z.cwiseAbs().maxCoeff()));
        CHECK(w.minCoeff() >= -1e-12);
        CHECK(z.minCoeff() >= 0.0);
        CHECK(std::abs(z.dot(w)) <= 1e-12);
      }
    }
  }
}

TEST_CASE("Sweeps that could not reach rounding within max_sweeps are not tried",
          "[banded][lcp]") {
  // ρ = 0.85 needs about 35 / -ln 0.85 = 218 sweeps from a cold start: more than the default
  // 200, so a dominance limit of 0.9 still factorises, and iterates with 300 sweeps allowed.
  std::mt19937 rng(12);
  const Matrix M = dominant(30, 3, 0.85, rng);
  BandedLcpOptions options;
  options.dominance_limit = 0.9;
  BandedLcpSolver capped(options);
  capped.set_matrix(M);
  CHECK(capped.dominance() > 0.8);
  CHECK_FALSE(capped.iterates());
  options.max_sweeps = 300;
  BandedLcpSolver allowed(options);
  allowed.set_matrix(M);
  CHECK(allowed.iterates());
  auto dense = make_block_pivoting_solver();
  dense->set_matrix(M);
  const Vector q = random_q(30, rng);
  for (BandedLcpSolver* s : {&capped, &allowed}) {
    const Solved a = solve(*s, q, Vector::Zero(30));
    const Solved d = solve(*dense, q, Vector::Zero(30));
    CHECK((a.z - d.z).cwiseAbs().maxCoeff() <= 1e-11 * (1 + d.z.cwiseAbs().maxCoeff()));
  }
  CHECK(capped.sweeps() == 0);
  CHECK(allowed.factorized_rows() == 0);
}

TEST_CASE("On the step's matrix the stepper's LCP reaches rounding in two sweeps per active set",
          "[banded][lcp]") {
  // The step's matrix is I + O(η²) (dominance ρ about 1e-7 here): a sweep from the previous
  // step's forces leaves an error of about ρ times the change, and the bound ρ/(1-ρ) times the
  // last move ends the sweeps on the second. Half the springs act, as on the paper's chain in
  // its first seconds.
  const BandedStepOperators ops =
      make_banded_step_operators(make_chain(paper_large_chain(200)), 0.02);
  const Matrix M = ops.lcp_matrix.to_dense();
  const Index n = M.rows();
  BandedLcpSolver stepper;
  stepper.set_matrix(ops.lcp_matrix);
  REQUIRE(stepper.iterates());
  auto dense = make_block_pivoting_solver();
  dense->set_matrix(M);
  Vector z = Vector::Zero(n);
  stepper.reset_active_set(z);
  long solves_with_active = 0;
  const long sweeps_before = stepper.sweeps();
  for (int k = 0; k < 50; ++k) {
    Vector q(n);
    for (Index i = 0; i < n; ++i) {
      q[i] = (i % 2 == 0 ? -1.0 : 0.5) * (1.0 + 0.3 * std::sin(0.02 * k + 0.1 * i));
    }
    const LcpResult r = stepper.solve_forces(q, z);
    const Solved d = solve(*dense, q, Vector::Zero(n));
    INFO("k " << k);
    CHECK((z - d.z).cwiseAbs().maxCoeff() <= 1e-14 * d.z.cwiseAbs().maxCoeff());
    CHECK(stepper.active_set().size() == static_cast<std::size_t>(n / 2));
    if (k > 0) CHECK(r.pivots == 0);
    ++solves_with_active;
  }
  // Two sweeps per solve once warm (the first solve starts from the forces that zero each
  // spring's own slack), where sweeping until a sweep no longer moves the forces takes three.
  CHECK(stepper.sweeps() - sweeps_before <= 2 * solves_with_active + 2);
}

TEST_CASE("The step's LCP matrix is dominant; bad matrices and input are reported",
          "[banded][lcp]") {
  const BandedStepOperators ops =
      make_banded_step_operators(make_chain(paper_large_chain(100)), 0.02);
  BandedLcpSolver s;
  s.set_matrix(ops.lcp_matrix);
  CHECK(s.iterates());
  CHECK(s.dominance() < 1e-3);
  CHECK(is_p_matrix(ops.lcp_matrix));

  // Zero diagonal: no P-matrix; the active set {0, 1} is singular.
  Matrix M(2, 2);
  M << 0.0, 1.0, 1.0, 0.0;
  BandedLcpSolver bad;
  bad.set_matrix(M);
  CHECK_FALSE(bad.iterates());
  std::string why;
  CHECK_FALSE(is_p_matrix(BandedMatrix::from_dense_nonzeros(M), &why));
  CHECK(!why.empty());
  Vector z = Vector::Zero(2), w = Vector::Zero(2);
  CHECK_THROWS_AS(bad.solve(Vector::Constant(2, -1.0), z, w), LcpError);

  BandedLcpSolver fresh;
  CHECK_THROWS_AS(fresh.solve(Vector::Ones(2), z, w), InputError);
  CHECK_THROWS_AS(fresh.set_matrix(Matrix::Ones(2, 3)), InputError);
  fresh.set_matrix(Matrix::Identity(2, 2));
  Vector nan_q(2);
  nan_q << 1.0, std::nan("");
  CHECK_THROWS_WITH(fresh.solve(nan_q, z, w), Catch::Contains("q[1]"));
  BandedLcpOptions o;
  o.dominance_limit = 1.5;
  CHECK_THROWS_WITH(BandedLcpSolver(o), Catch::Contains("dominance_limit = 1.5"));
}
