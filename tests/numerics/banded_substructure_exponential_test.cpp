// Substructure exponentials against the exponential of the whole structure (precise_exponential
// on the dense state matrix, and Eigen's MatrixFunctions exp as a second opinion).
#include <catch2/catch.hpp>

#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/numerics/substructure_exponential.hpp"
#include "test_structures.hpp"

using namespace pwl;

namespace {

double max_abs(const Matrix& A) { return A.size() ? A.cwiseAbs().maxCoeff() : 0.0; }

// Random cells, uniform gap springs (test_structures.hpp).
ChainParameters varying_chain(int n, unsigned seed) {
  return pwl::test::varying_chain(n, seed, 0.1, false);
}

}  // namespace

TEST_CASE("The whole structure as a substructure gives the dense step's exponential", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(12));
  const double eta = 0.3;
  const std::vector<LoadGroup> groups = s.load_groups();
  REQUIRE(groups.size() == 2);
  const SubstructureExponential e = substructure_exponential(s, 0, 12, eta, groups);
  const PimStepOperators ops = make_pim_step_operators(s, eta);
  CHECK(max_abs(e.transition - ops.transition) < 1e-14);
  CHECK(max_abs(substructure_state_matrix(s, 0, 12) - state_matrix(s)) == 0.0);
  // Eigen's Padé exponential, independently of the 2^N algorithm.
  const Matrix reference = (state_matrix(s) * eta).exp();
  CHECK(max_abs(e.transition - reference) < 1e-13);
  // Unit mass and W = I (ground springs): Φ = rising_load · (-I), Ψ = falling_load · (-I).
  CHECK(max_abs(e.rising_load + ops.force_next) < 1e-15);
  CHECK(max_abs(e.falling_load + ops.force_now) < 1e-15);
  // The responses to the loads equal the dense step's.
  for (std::size_t g = 0; g < 2; ++g) {
    CHECK(e.harmonics[g].omega == ops.harmonics[g].omega);
    CHECK((e.harmonics[g].sin_response - ops.harmonics[g].sin_response).cwiseAbs().maxCoeff() <
          1e-15);
    CHECK((e.harmonics[g].cos_response - ops.harmonics[g].cos_response).cwiseAbs().maxCoeff() <
          1e-15);
  }
}

TEST_CASE("A row of a substructure equals that row of the whole structure's exponential",
          "[banded]") {
  // Energy does not reach the cut within the step, so row i of a substructure reaching R beyond
  // it matches the whole chain, and the mismatch shrinks quickly as R grows.
  const Index n = 60;
  const GapStructure s = make_chain(varying_chain(static_cast<int>(n), 7));
  const double eta = 0.5;
  const Matrix T = (state_matrix(s) * eta).exp();
  const Index i = 30;
  double previous = 1.0;
  for (Index R : {3, 6, 9, 12, 15}) {
    const SubstructureExponential e = substructure_exponential(s, i - R, i + R + 1, eta, {});
    const Index w = 2 * R + 1, li = R;
    double mismatch = 0.0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b)
        for (Index lj = 0; lj < w; ++lj)
          mismatch = std::max(mismatch, std::abs(e.transition(a * w + li, b * w + lj) -
                                                 T(a * n + i, b * n + i - R + lj)));
    INFO("R = " << R << ": mismatch " << mismatch);
    // Down by orders of magnitude each time, until rounding.
    CHECK((mismatch < previous / 100 || mismatch < 2e-15));
    previous = mismatch;
  }
  CHECK(previous < 2e-15);
}

TEST_CASE("Substructure keys tell repeated content from different content", "[banded]") {
  const GapStructure uniform = make_chain(paper_large_chain(40));
  // Interior windows of a uniform chain are the same substructure, wherever they sit; the one at
  // the wall too (the wall acts like a held neighbour); the one holding the free end differs.
  CHECK(SubstructureKey(uniform, 5, 16) == SubstructureKey(uniform, 20, 31));
  CHECK(SubstructureKey(uniform, 0, 11) == SubstructureKey(uniform, 20, 31));
  CHECK(!(SubstructureKey(uniform, 29, 40) == SubstructureKey(uniform, 20, 31)));
  CHECK(!(SubstructureKey(uniform, 20, 30) == SubstructureKey(uniform, 20, 31)));
  ChainParameters p = paper_large_chain(40);
  p.mass.assign(40, 1.0);
  p.mass[25] = 1.5;
  const GapStructure bumped = make_chain(p);
  CHECK(!(SubstructureKey(bumped, 20, 31) == SubstructureKey(uniform, 20, 31)));
  CHECK(SubstructureKey(bumped, 2, 13) == SubstructureKey(uniform, 20, 31));
  // Loads on the window are part of the content: the paper's loads alternate from mass to mass.
  const std::vector<LoadGroup> loads = uniform.load_groups();
  CHECK(SubstructureKey(uniform, 4, 15, loads) == SubstructureKey(uniform, 20, 31, loads));
  CHECK(!(SubstructureKey(uniform, 5, 16, loads) == SubstructureKey(uniform, 20, 31, loads)));
  CHECK_THROWS_AS(SubstructureKey(uniform, 35, 41), InputError);
  CHECK_THROWS_AS(substructure_exponential(uniform, 5, 5, 0.1, {}), InputError);
}

TEST_CASE("Cell sizes are detected from the repeating matrices", "[banded]") {
  CHECK(detect_cell_size(make_chain(paper_large_chain(50))) == 1);
  ChainParameters alternating = paper_large_chain(50);
  alternating.mass.clear();
  for (int i = 0; i < 50; ++i) alternating.mass.push_back(i % 2 ? 2.0 : 1.0);
  CHECK(detect_cell_size(make_chain(alternating)) == 2);
  CHECK(detect_cell_size(make_chain(varying_chain(50, 3))) == 0);
}
