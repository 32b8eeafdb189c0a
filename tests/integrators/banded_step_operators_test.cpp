// The banded step operators against the dense ones of pim_step_operators.hpp, on a structure
// with both kinds of springs (to the ground and between neighbours, either direction), listed
// out of order, with masses that vary.
#include <catch2/catch.hpp>

#include <algorithm>
#include <random>

#include "pwl/integrators/banded_step_operators.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_step_operators.hpp"

using namespace pwl;

namespace {

GapStructure mixed_chain(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  ChainParameters p = paper_large_chain(n);
  p.mass.clear();
  for (int i = 0; i < n; ++i) p.mass.push_back(u(rng));
  p.k2 = {3.0};
  p.gap = {0.05};
  GapStructure s = make_chain(p);
  // Clearances between neighbours (both directions) and ground springs pulling the other way.
  for (int i = 0; i + 1 < n; i += 3) s.springs.push_back({i + 1, i, 1.0, 2.0 * u(rng), 0.1});
  for (int i = 2; i + 1 < n; i += 5) s.springs.push_back({i, i + 1, -1.0, 1.5, 0.02});
  for (int i = 1; i < n; i += 4) s.springs.push_back({i, -1, -1.0, 0.7, 0.3});
  std::shuffle(s.springs.begin(), s.springs.end(), rng);
  s.validate();
  return s;
}

// Largest |banded - dense| over a state operator's rows (interleaved against [x; x']) and the
// spring columns (banded numbering against the structure's).
double force_error(const BandedMatrix& B, const Matrix& D, const std::vector<Index>& order) {
  const Index n = D.rows() / 2;
  double worst = 0.0;
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < 2; ++a)
      for (Index j = 0; j < D.cols(); ++j)
        worst = std::max(worst, std::abs(B.coeff(2 * i + a, j) -
                                         D(a * n + i, order[static_cast<std::size_t>(j)])));
  return worst;
}

}  // namespace

TEST_CASE("Banded step operators equal the dense step's", "[banded]") {
  const int n = 70;
  const GapStructure s = mixed_chain(n, 5);
  const Index m = s.spring_count();
  for (double eta : {0.03, 0.25}) {
    const BandedStepOperators b = make_banded_step_operators(s, eta);
    const PimStepOperators d = make_pim_step_operators(s, eta);
    INFO("eta " << eta << ": band " << b.truncation.band);
    REQUIRE(b.spring_order.size() == static_cast<std::size_t>(m));
    // The springs are renumbered by position, so the LCP matrix is banded.
    for (Index j = 1; j < m; ++j) {
      const GapSpring& prev = s.springs[static_cast<std::size_t>(b.spring_order[static_cast<std::size_t>(j - 1)])];
      const GapSpring& next = s.springs[static_cast<std::size_t>(b.spring_order[static_cast<std::size_t>(j)])];
      CHECK(std::min(prev.dof, prev.other_dof >= 0 ? prev.other_dof : prev.dof) <=
            std::min(next.dof, next.other_dof >= 0 ? next.other_dof : next.dof));
    }
    const double phi_scale = d.force_next.cwiseAbs().maxCoeff();
    const double psi_scale = d.force_now.cwiseAbs().maxCoeff();
    CHECK(force_error(b.force_next, d.force_next, b.spring_order) <= 1e-14 * phi_scale);
    CHECK(force_error(b.force_now, d.force_now, b.spring_order) <= 1e-14 * psi_scale);
    double lcp = 0.0;
    for (Index i = 0; i < m; ++i)
      for (Index j = 0; j < m; ++j)
        lcp = std::max(lcp, std::abs(b.lcp_matrix.coeff(i, j) -
                                     d.lcp_matrix(b.spring_order[static_cast<std::size_t>(i)],
                                                  b.spring_order[static_cast<std::size_t>(j)])));
    CHECK(lcp <= 1e-15);
    CHECK(b.lcp_matrix.width() < m / 2);
    for (Index j = 0; j < m; ++j) {
      const auto k = static_cast<std::size_t>(b.spring_order[static_cast<std::size_t>(j)]);
      CHECK(b.gaps[j] == s.springs[k].gap);
      CHECK(b.stiffnesses[j] == s.springs[k].stiffness);
    }
    REQUIRE(b.harmonics.size() == d.harmonics.size());
    for (std::size_t g = 0; g < d.harmonics.size(); ++g)
      for (Index i = 0; i < n; ++i)
        for (int a = 0; a < 2; ++a) {
          CHECK(std::abs(b.harmonics[g].sin_response[2 * i + a] -
                         d.harmonics[g].sin_response[a * n + i]) < 1e-15);
          CHECK(std::abs(b.harmonics[g].cos_response[2 * i + a] -
                         d.harmonics[g].cos_response[a * n + i]) < 1e-15);
        }
  }
}

TEST_CASE("A structure without springs or loads has empty spring operators", "[banded]") {
  ChainParameters p = paper_large_chain(20);
  p.loads.clear();
  GapStructure s = make_chain(p);
  s.springs.clear();
  const BandedStepOperators b = make_banded_step_operators(s, 0.1);
  CHECK(b.force_next.cols() == 0);
  CHECK(b.lcp_matrix.rows() == 0);
  CHECK(b.harmonics.empty());
  CHECK(b.transition.rows() == 40);
}
