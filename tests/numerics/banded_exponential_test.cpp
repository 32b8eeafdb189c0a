// The banded exponential against the dense exponential of the whole structure: what the band
// drops is within the stated bound, the band is the smallest that is, and the reported bound is
// the measured one.
#include <catch2/catch.hpp>

#include <array>
#include <random>

#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/numerics/precise_exponential.hpp"
#include "test_structures.hpp"

using namespace pwl;

namespace {

// Independently computed exponentials agree to rounding of ~20 doublings, not to the last bit.
constexpr double kRounding = 4e-15;

// Per block (a, b) of a dense 2n x 2n state operator in [x; x'] layout: ‖block‖∞.
std::array<double, 4> block_norms(const Matrix& D, Index n) {
  std::array<double, 4> out{};
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      out[2 * a + b] = D.block(a * n, b * n, n, n).cwiseAbs().rowwise().sum().maxCoeff();
  return out;
}

// Per block: max over rows of Σ_{|i-j| > q} |D_ij| / ‖block‖∞.
double dense_tail(const Matrix& D, Index n, Index q) {
  const auto norms = block_norms(D, n);
  double worst = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (Index i = 0; i < n; ++i) {
        double tail = 0.0;
        for (Index j = 0; j < n; ++j)
          if (std::abs(i - j) > q) tail += std::abs(D(a * n + i, b * n + j));
        worst = std::max(worst, tail / norms[2 * a + b]);
      }
  return worst;
}

// Per block: ‖banded - dense‖∞ / ‖dense block‖∞, the banded one on the interleaved state.
double banded_error(const BandedMatrix& B, const Matrix& D, Index n) {
  const auto norms = block_norms(D, n);
  double worst = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (Index i = 0; i < n; ++i) {
        double sum = 0.0;
        for (Index j = 0; j < n; ++j)
          sum += std::abs(B.coeff(2 * i + a, 2 * j + b) - D(a * n + i, b * n + j));
        worst = std::max(worst, sum / norms[2 * a + b]);
      }
  return worst;
}

// Random cells, gap springs too (test_structures.hpp).
ChainParameters varying_chain(int n, unsigned seed) {
  return pwl::test::varying_chain(n, seed, 0.2, true);
}

}  // namespace

TEST_CASE("Banded T equals the dense exponential to the stated tolerance", "[banded]") {
  for (double tol : {1e-15, 1e-10}) {
    for (int n : {12, 40, 90}) {
      if (tol > 1e-15 && n != 40) continue;
      const GapStructure s = make_chain(paper_large_chain(n));
      for (double eta : {0.02, 0.3, 1.5}) {
        BandedExponentialOptions o;
        o.tolerance = tol;
        const BandedExponential b = make_banded_exponential(s, eta, o);
        const Matrix T = precise_exponential(state_matrix(s), eta);
        const Index q = b.truncation.band;
        INFO("tol " << tol << ", n " << n << ", eta " << eta << ": band " << q << ", dropped "
                    << b.truncation.dropped_ratio);
        CHECK(b.truncation.within_tolerance());
        CHECK(banded_error(b.transition, T, n) <= tol + kRounding);
        // The band is the smallest within the tolerance (unless it spans the whole chain).
        if (q > 0 && q < n - 1) CHECK(dense_tail(T, n, q - 1) > tol);
        // The reported bound is the dropped part measured on the whole exponential (T dominates
        // what is dropped for these chains).
        CHECK(b.truncation.dropped_ratio ==
              Approx(std::max(dense_tail(T, n, q), 0.0)).epsilon(0.02).margin(kRounding));
      }
    }
  }
}

TEST_CASE("The band grows with the step and does not depend on the chain's length", "[banded]") {
  Index previous = 0;
  for (double eta : {0.02, 0.16, 1.0}) {
    const BandedExponential small = make_banded_exponential(make_chain(paper_large_chain(100)), eta);
    const BandedExponential large = make_banded_exponential(make_chain(paper_large_chain(400)), eta);
    INFO("eta " << eta);
    CHECK(small.truncation.band == large.truncation.band);
    CHECK(small.truncation.band > previous);
    previous = small.truncation.band;
    // A periodic chain needs a handful of substructures and stores a handful of distinct rows,
    // whatever its length.
    CHECK(small.truncation.cell_dofs == 1);
    CHECK(large.truncation.exponentials == small.truncation.exponentials);
    // Left end, interior (two: the loads alternate), next to the free end, free end.
    CHECK(large.truncation.exponentials <= 5);
    CHECK(large.transition.stored_rows() == small.transition.stored_rows());
    CHECK(large.transition.stored_rows() < 8 * (2 * large.truncation.band + 2));
  }
  // The paper's chain at its step: the 11-dof substructure (q = 5) meets 1e-15.
  CHECK(make_banded_exponential(make_chain(paper_large_chain(1000)), 0.02).truncation.band == 5);
}

TEST_CASE("Chains whose cells differ get their band from local substructures", "[banded]") {
  const int n = 80;
  const GapStructure s = make_chain(varying_chain(n, 11));
  for (double eta : {0.05, 0.4}) {
    const BandedExponential b = make_banded_exponential(s, eta);
    const PimStepOperators ops = make_pim_step_operators(s, eta);
    INFO("eta " << eta << ": band " << b.truncation.band);
    CHECK(b.truncation.cell_dofs == 0);
    CHECK(b.truncation.exponentials > 4);
    CHECK(b.truncation.within_tolerance());
    CHECK(banded_error(b.transition, ops.transition, n) <= b.truncation.tolerance + kRounding);
    // Harmonic responses (interleaved) against the dense ones.
    for (std::size_t g = 0; g < ops.harmonics.size(); ++g) {
      for (Index i = 0; i < n; ++i)
        for (int a = 0; a < 2; ++a) {
          CHECK(std::abs(b.harmonics[g].sin_response[2 * i + a] -
                         ops.harmonics[g].sin_response[a * n + i]) < 1e-15);
          CHECK(std::abs(b.harmonics[g].cos_response[2 * i + a] -
                         ops.harmonics[g].cos_response[a * n + i]) < 1e-15);
        }
    }
  }
  // A periodic chain with loads that alternate (windows repeat every two masses) and local
  // defects outside its middle half (still cell 1): the rows near a defect come from their own
  // substructures, the repeating stretches reuse one (CellRepeats); T and the load responses
  // against the dense ones.
  {
    ChainParameters p = paper_large_chain(90);
    p.k1.assign(90, 1.0);
    p.k1[12] = 3.0;
    p.damping.assign(90, 0.2);
    p.damping[75] = 0.5;
    p.loads[80].amplitude = -0.7;
    const GapStructure d = make_chain(p);
    const BandedExponential b = make_banded_exponential(d, 0.1);
    CHECK(b.truncation.cell_dofs == 1);
    const PimStepOperators ops = make_pim_step_operators(d, 0.1);
    CHECK(banded_error(b.transition, ops.transition, 90) <= b.truncation.tolerance + kRounding);
    for (std::size_t g = 0; g < ops.harmonics.size(); ++g) {
      double worst = 0.0;
      for (Index i = 0; i < 90; ++i)
        for (int a = 0; a < 2; ++a) {
          worst = std::max({worst,
                            std::abs(b.harmonics[g].sin_response[2 * i + a] -
                                     ops.harmonics[g].sin_response[a * 90 + i]),
                            std::abs(b.harmonics[g].cos_response[2 * i + a] -
                                     ops.harmonics[g].cos_response[a * 90 + i])});
        }
      CHECK(worst < 1e-15);
    }
  }
  // Cells of two masses that alternate are detected and give the same result as undeclared.
  ChainParameters alternating = paper_large_chain(60);
  alternating.mass.clear();
  for (int i = 0; i < 60; ++i) alternating.mass.push_back(i % 2 ? 3.0 : 1.0);
  const GapStructure a = make_chain(alternating);
  const BandedExponential detected = make_banded_exponential(a, 0.1);
  CHECK(detected.truncation.cell_dofs == 2);
  CHECK(detected.truncation.exponentials <= 8);
  CHECK(banded_error(detected.transition, precise_exponential(state_matrix(a), 0.1), 60) <=
        1e-15 + kRounding);
}

TEST_CASE("A forced band reports what it drops; bad input is named", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(50));
  BandedExponentialOptions o;
  o.band = 2;
  const BandedExponential b = make_banded_exponential(s, 0.1, o);
  const Matrix T = precise_exponential(state_matrix(s), 0.1);
  CHECK(b.truncation.band == 2);
  CHECK_FALSE(b.truncation.within_tolerance());
  CHECK(b.truncation.dropped_ratio == Approx(dense_tail(T, 50, 2)).epsilon(0.02));
  CHECK(banded_error(b.transition, T, 50) == Approx(dense_tail(T, 50, 2)).epsilon(0.02));

  BandedExponentialOptions bad;
  bad.tolerance = 0.0;
  CHECK_THROWS_WITH(make_banded_exponential(s, 0.1, bad), Catch::Contains("tolerance = 0"));
  CHECK_THROWS_AS(make_banded_exponential(s, -1.0), InputError);
  GapStructure consistent = s;
  consistent.mass.coeffRef(0, 1) = 0.1;
  consistent.mass.coeffRef(1, 0) = 0.1;
  CHECK_THROWS_WITH(make_banded_exponential(consistent, 0.1), Catch::Contains("diagonal"));
  BandedExponentialOptions narrow;
  narrow.max_band = 3;
  CHECK_THROWS_WITH(make_banded_exponential(s, 5.0, narrow), Catch::Contains("max_band = 3"));
}
