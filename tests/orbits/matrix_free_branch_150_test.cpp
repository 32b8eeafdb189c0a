// Matrix-free continuation (Newton–Krylov on the bordered system, Arnoldi's leading multipliers,
// no monodromy formed) against the dense continuation (the whole monodromy at every point) on the
// same branch of a 150-mass chain, whose period-1 orbit loses stability at two Neimark–Sacker
// points below θ = 0.74, past grazings: the same bifurcations, located to within 1e-8 of each
// other, the same stability at every point, and the leading multipliers at its points equal to
// the eigenvalues of the monodromy formed there, every one of them in the band |μ| > 0.99 among
// the reported (ArnoldiOptions::margin). (Release build only: 43 s there.)
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "continuation_cases.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;
using pwl::test::follow;
using pwl::test::paper_chain;
using pwl::test::settled_guess;


TEST_CASE("the 150-mass chain's branch is the same matrix-free as dense", "[orbits]") {
  const double from = 0.745, to = 0.70;
  const NondimensionalChain chain = paper_chain(150, from);
  const MethodSettings method{Method::pim_switching_banded};
  const Vector guess = settled_guess(chain, method, 200);
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = from;
  o.end = to;
  o.method = method;
  o.steps_per_period = 200;
  o.max_points = 200;
  // Arnoldi covers the band |μ| > 0.99 at every matrix-free point (the dense monodromy has all).
  const double margin = 0.01;
  o.shooting.arnoldi.margin = margin;
  const ContinuationResult dense = follow(chain, guess, o, ShootingSolver::dense);
  const ContinuationResult free = follow(chain, guess, o, ShootingSolver::krylov);
  REQUIRE_FALSE(dense.matrix_free);
  REQUIRE(free.matrix_free);
  CHECK(free.monodromies == 0);
  CHECK(free.krylov_products > 0);
  CHECK(free.arnoldi_products > 0);
  CHECK(free.unconverged_multipliers == 0);
  // The chain's damping is classical: every point's multipliers by Davidson preconditioned by the
  // open structure (trial points of the locations too), none by Arnoldi; dense, neither.
  CHECK(free.davidson_points >= static_cast<long>(free.points.size()));
  CHECK(free.arnoldi_points == 0);
  CHECK(dense.davidson_points + dense.arnoldi_points == 0);
  // Every point covered the margin, so the band watched between points was never narrowed below
  // it (only the leading multipliers are known matrix-free; dense, all of them).
  CHECK(free.uncovered_bands == 0);
  REQUIRE(std::isfinite(free.narrowest_band));  // steps were checked
  CHECK(free.narrowest_band >= margin);
  CHECK(dense.narrowest_band == std::max(o.band, margin));
  CHECK(dense.band == o.band);  // dense: the band asked, not widened
  CHECK(free.band == std::max(o.band, margin));

  // The same bifurcations in the same order, each within 1e-8 in θ.
  int neimark_sacker = 0;
  REQUIRE(dense.bifurcations.size() == free.bifurcations.size());
  double worst = 0;
  for (std::size_t i = 0; i < dense.bifurcations.size(); ++i) {
    const Bifurcation& d = dense.bifurcations[i];
    const Bifurcation& f = free.bifurcations[i];
    INFO("bifurcation " << i << ": " << bifurcation_name(d.type) << " at " << d.parameter
                        << " (dense), " << bifurcation_name(f.type) << " at " << f.parameter);
    CHECK(d.type == f.type);
    CHECK(d.spring == f.spring);
    CHECK(d.at_largest_gap == f.at_largest_gap);
    CHECK(f.located);
    worst = std::max(worst, std::abs(d.parameter - f.parameter));
    CHECK(std::abs(d.parameter - f.parameter) <= 1e-8);
    if (d.type == BifurcationType::neimark_sacker) {
      ++neimark_sacker;
      CHECK(std::abs(std::abs(f.multiplier) - 1.0) <= 1e-6);
      CHECK(std::abs(f.multiplier - d.multiplier) <= 1e-6);
    }
  }
  measured("150 masses: largest distance of a matrix-free bifurcation from the dense one", worst);
  CHECK(neimark_sacker == 2);

  // The same stability: at every matrix-free point, as many multipliers outside the circle as at
  // the dense branch's point nearest it when no bifurcation lies between the two.
  for (const BranchPoint& p : free.points) {
    const BranchPoint* q = pwl::test::nearest_point(dense, 0, p.parameter);
    REQUIRE(q != nullptr);
    const double at = q->parameter;
    const int expected = q->orbit.multipliers.unstable_count();
    bool between = false;
    for (const Bifurcation& b : dense.bifurcations) {
      if (b.type == BifurcationType::grazing) continue;
      between = between || (b.parameter - p.parameter) * (b.parameter - at) <= 0;
    }
    if (between) continue;
    INFO("theta = " << p.parameter << " (dense point at " << at << ")");
    CHECK(p.orbit.multipliers.unstable_count() == expected);
    CHECK_FALSE(p.orbit.multipliers.complete);
  }

  // The leading multipliers at three points equal the eigenvalues of the monodromy formed there,
  // and every eigenvalue in the band is among them.
  double distance = 0, band = 0;
  std::size_t widest = 0;
  for (const std::size_t i : {std::size_t{0}, free.points.size() / 2, free.points.size() - 1}) {
    const BranchPoint& p = free.points[i];
    StroboscopicMap map(analysis::PointCase(paper_chain(150, p.parameter)), method, 200);
    Matrix M;
    const Vector end = map.advance_with_jacobian(p.orbit.state, 1, M);
    CHECK((end - p.orbit.state).lpNorm<Eigen::Infinity>() <= 1e-9);
    const FloquetMultipliers all = floquet_multipliers(M);
    const auto& leading = p.orbit.multipliers.values;
    const std::vector<std::complex<double>> expected(all.values.begin(),
                                                     all.values.begin() + leading.size());
    distance = std::max(distance, pwl::test::set_distance(expected, leading));
    CHECK(p.orbit.multipliers.band_covered);
    std::size_t in_band = 0;
    band = std::max(band, pwl::test::farthest_in_band(all.values, leading, margin, &in_band));
    CHECK(leading.size() >= in_band);
    widest = std::max(widest, in_band);
  }
  measured("150 masses: leading multipliers against the monodromy's eigenvalues", distance);
  measured("150 masses: farthest eigenvalue of the band |mu| > 0.99 from a reported multiplier",
           band);
  measured("150 masses: most eigenvalues in the band at one of the three points",
           static_cast<double>(widest));
  CHECK(distance <= 1e-8);
  CHECK(band <= 1e-8);
  CHECK(widest > 6);  // more than Arnoldi's default count: the band made it report them
}
