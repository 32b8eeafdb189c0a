// Matrix-free shooting against the dense form: on a 50-mass chain (100 state components, springs
// that open and close every period), Newton-Krylov (GMRES on tangent products) and dense Newton
// (the whole monodromy, LU) must land on the same orbit, and restarted Arnoldi's leading Floquet
// multipliers must be the leading eigenvalues of the dense monodromy. Restarted Arnoldi alone on a
// matrix whose eigenvalues are known by construction.
#include <Eigen/QR>
#include <omp.h>
#include <algorithm>
#include <catch2/catch.hpp>
#include <complex>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include "known_spectra.hpp"
#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;
using pwl::test::put_pair;
using pwl::test::set_distance;
using Complex = std::complex<double>;

namespace {

// S D S⁻¹ with S a random well-conditioned basis (known_spectra.hpp).
Matrix similar_to(const Matrix& D, std::mt19937& rng) {
  const Matrix S = pwl::test::random_basis(D.rows(), rng);
  return S * D * S.inverse();
}

// The figure 4a chain (α = 2, Δ̃ = 0, Q = 1 on every mass) at θ = 1.5: springs that open and
// close every period.
NondimensionalChain contact_chain(int masses) {
  NondimensionalChain chain;
  chain.masses = masses;
  chain.alpha = {2.0};
  chain.gap = {0.0};
  chain.amplitude = {1.0};
  chain.theta = 1.5;
  return chain;
}

StroboscopicMap banded_switching_map(const NondimensionalChain& chain) {
  return StroboscopicMap(analysis::PointCase(chain), MethodSettings{Method::pim_switching_banded},
                         100);
}

}  // namespace

TEST_CASE("Newton-Krylov and dense Newton find the same periodic orbit of a 50-mass chain",
          "[orbits]") {
  const NondimensionalChain chain = contact_chain(50);
  // A 100x100 problem gains nothing from Eigen's threads, and on a loaded machine their spinning
  // costs seconds.
  Eigen::setNbThreads(1);
  // The dense PIM has the exact tangent map (the banded form, which "pim" picks beyond 50 masses,
  // would give forward-difference products of about eight digits).
  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::pim_dense}, 100);
  REQUIRE(map.exact_tangent());
  // From the steady response of the chain with its springs open: the slow modes' multipliers are
  // within 1e-3 of the unit circle, so a seed from the transient would take thousands of periods.
  const Vector seed = pwl::test::harmonic_response(map.structure(), chain.theta);

  ShootingOptions options;
  options.tolerance = 1e-12;
  options.solver = ShootingSolver::dense;
  const PeriodicOrbit dense = find_periodic_orbit(map, seed, options);
  options.solver = ShootingSolver::krylov;
  options.arnoldi.count = 6;
  // The progress hook sees every iteration in order, with the GMRES products spent so far.
  std::vector<int> iterations;
  std::vector<long> products;
  double last_residual = -1.0;
  options.on_iteration = [&](int iteration, double residual, long spent) {
    iterations.push_back(iteration);
    products.push_back(spent);
    last_residual = residual;
  };
  const PeriodicOrbit krylov = find_periodic_orbit(map, seed, options);
  REQUIRE(iterations.size() == static_cast<std::size_t>(krylov.iterations) + 1);
  for (std::size_t i = 0; i < iterations.size(); ++i) CHECK(iterations[i] == static_cast<int>(i));
  CHECK(products.front() == 0);
  CHECK(products.back() == krylov.krylov_products);
  CHECK(std::is_sorted(products.begin(), products.end()));
  CHECK(last_residual == krylov.residual);
  REQUIRE(dense.solver == ShootingSolver::dense);
  REQUIRE(krylov.solver == ShootingSolver::krylov);
  CHECK(krylov.monodromy.size() == 0);

  // Contacts open and close along it (not a linear problem in disguise).
  const OrbitProfile profile = orbit_profile(map, dense.state, 1);
  const auto touching = (profile.max_gap.array() > 0).count();
  CHECK(touching > 0);
  CHECK(touching < 50);

  const double difference = (krylov.state - dense.state).lpNorm<Eigen::Infinity>();
  measured(
      "krylov vs dense orbit (|y| " + std::to_string(dense.state.lpNorm<Eigen::Infinity>()) + ")",
      difference);
  CHECK(difference <= 1e-9);
  CHECK(krylov.residual <= 1e-12 * std::max(1.0, krylov.state.lpNorm<Eigen::Infinity>()));

  // The leading six: lightly damped slow modes, three complex pairs just inside the unit circle.
  REQUIRE(dense.multipliers.values.size() == 100);
  REQUIRE(krylov.multipliers.values.size() == 6);
  CHECK_FALSE(krylov.multipliers.complete);
  const std::vector<Complex> leading(dense.multipliers.values.begin(),
                                     dense.multipliers.values.begin() + 6);
  const double distance = set_distance(leading, krylov.multipliers.values);
  measured("Arnoldi vs dense leading multipliers", distance);
  CHECK(distance <= 1e-8);
  CHECK(krylov.multipliers.largest_modulus() > 0.99);
  CHECK(krylov.stable());
}

TEST_CASE("Newton-Krylov on the banded switching PIM replays its tangent products", "[orbits]") {
  // The 50-mass chain by the banded switching PIM, whose tangent map the stroboscopic map records
  // on a Krylov method's first product and replays for the next ones from the same state: dense
  // Newton (whole monodromies, never replayed) and Newton-Krylov must land on the same orbit, with
  // the same leading multipliers, and the replays must have replaced most integrations.
  const NondimensionalChain chain = contact_chain(50);
  Eigen::setNbThreads(1);
  StroboscopicMap dense_map = banded_switching_map(chain), krylov_map = banded_switching_map(chain);
  REQUIRE(krylov_map.exact_tangent());
  REQUIRE(krylov_map.integrator().can_record_tangent());
  const Vector seed = pwl::test::harmonic_response(krylov_map.structure(), chain.theta);
  ShootingOptions options;
  options.tolerance = 1e-12;
  options.solver = ShootingSolver::dense;
  const PeriodicOrbit dense = find_periodic_orbit(dense_map, seed, options);
  CHECK(dense_map.tangent_replays() == 0);
  options.solver = ShootingSolver::krylov;
  options.arnoldi.count = 6;
  const PeriodicOrbit krylov = find_periodic_orbit(krylov_map, seed, options);
  const double difference = (krylov.state - dense.state).lpNorm<Eigen::Infinity>();
  measured("banded switching PIM: krylov vs dense orbit", difference);
  CHECK(difference <= 1e-9);
  const std::vector<Complex> leading(dense.multipliers.values.begin(),
                                     dense.multipliers.values.begin() + 6);
  const double distance = set_distance(leading, krylov.multipliers.values);
  measured("banded switching PIM: Arnoldi vs dense leading multipliers", distance);
  CHECK(distance <= 1e-8);
  measured("integrations", static_cast<double>(krylov_map.evaluations()));
  measured("replayed products", static_cast<double>(krylov_map.tangent_replays()));
  // Without replays every GMRES product would be an integration, besides Newton's residuals.
  CHECK(krylov_map.tangent_replays() > krylov.krylov_products / 2);
  CHECK(krylov_map.evaluations() < krylov.krylov_products);
}

TEST_CASE("the stroboscopic map replays a plain evaluation's tangent, not a long transient's",
          "[orbits]") {
  // The banded switching PIM's map records plain integrations too: a product from the state just
  // evaluated, over the same span, is a replay, bit for bit the product a fresh map integrates.
  // A plain run of more than 64 periods is not recorded: its product integrates again.
  const NondimensionalChain chain = contact_chain(40);
  StroboscopicMap map = banded_switching_map(chain), fresh = banded_switching_map(chain);
  const Vector y = pwl::test::harmonic_response(map.structure(), chain.theta);
  Matrix V(map.state_size(), 2);
  for (Index i = 0; i < V.rows(); ++i) {
    V(i, 0) = std::sin(0.3 + 0.9 * static_cast<double>(i));
    V(i, 1) = std::cos(1.1 + 0.4 * static_cast<double>(i));
  }
  for (const int periods : {1, 2}) {
    INFO(periods << " period(s)");
    const Vector end = map.advance(y, periods);
    const long evaluations = map.evaluations(), replays = map.tangent_replays();
    Matrix replayed = V, integrated = V;
    const Vector end_replayed = map.advance(y, periods, replayed);
    const Vector end_integrated = fresh.advance(y, periods, integrated);
    CHECK(map.tangent_replays() == replays + 1);
    CHECK(map.evaluations() == evaluations);
    CHECK((end_replayed - end_integrated).cwiseAbs().maxCoeff() == 0.0);
    CHECK((end - end_integrated).cwiseAbs().maxCoeff() == 0.0);
    CHECK((replayed - integrated).cwiseAbs().maxCoeff() == 0.0);
    CHECK(integrated.cwiseAbs().maxCoeff() > 0.1);
  }
  // A long transient: not recorded, its product is an integration.
  map.advance(y, 65);
  const long evaluations = map.evaluations(), replays = map.tangent_replays();
  Matrix long_product = V;
  map.advance(y, 65, long_product);
  CHECK(map.tangent_replays() == replays);
  CHECK(map.evaluations() == evaluations + 1);
  // And from there on the map records again.
  map.advance(y, 1);
  Matrix again = V;
  map.advance(y, 1, again);
  CHECK(map.tangent_replays() == replays + 1);
}

TEST_CASE("thick-restarted Arnoldi resolves long-wave multipliers crowded against 1",
          "[orbits][release-only]") {
  // A = S D S⁻¹ of size 1000 with the spectrum of a long chain's orbit: the long-wave modes crowd
  // against μ = 1, μ_k = (1 − 4e-6 k²) e^{±0.0131 k i} for k = 1 .. 200 (the law the 1000-mass
  // chain of `pwl bench orbits` follows, where the dense monodromy's leading pairs are 0.999996,
  // 0.999984, 0.999964 at angles 0.0131, 0.0262, 0.0393), the other 600 in a disc of radius 0.9;
  // S a random well-conditioned basis. The default options must find the leading six; a basis of
  // 60 vectors, restarted as often, must not have converged (why the default is larger).
  const Index n = 1000;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix D = Matrix::Zero(n, n);
  std::vector<Complex> expected;
  for (int k = 1; k <= 200; ++k) {
    const double r = 1.0 - 4e-6 * k * k, phi = 0.0131 * k;
    put_pair(D, 2 * (k - 1), r, phi);
    if (k <= 3) {
      expected.push_back(std::polar(r, phi));
      expected.push_back(std::polar(r, -phi));
    }
  }
  for (Index i = 400; i + 1 < n; i += 2) put_pair(D, i, 0.9 * std::abs(u(rng)), 3.2 * u(rng));
  const Matrix A = similar_to(D, rng);
  long products = 0;
  const auto apply = [&](Matrix& v) {
    products += v.cols();
    v = A * v;
  };
  ArnoldiOptions options;
  options.count = 6;
  // Plain Arnoldi, and block Krylov-Schur taking 2 and 3 columns a product.
  for (const int block : {1, 2, 3}) {
    INFO("block " << block);
    options.block = block;
    products = 0;
    long calls = 0, wrong_width = 0;
    const FloquetMultipliers found = leading_floquet_multipliers(
        [&](Matrix& v) {
          ++calls;
          if (v.cols() != block) ++wrong_width;
          apply(v);
        },
        n, options);
    measured("crowded multipliers: residual", found.residual);
    measured("crowded multipliers: products", static_cast<double>(products));
    CHECK(wrong_width == 0);
    CHECK(products == calls * block);
    CHECK(found.converged);
    const double distance = set_distance(expected, found.values);
    measured("crowded multipliers: error", distance);
    CHECK(distance <= 1e-9);
    CHECK(found.largest_modulus() == Approx(1.0 - 4e-6).epsilon(1e-12));
    CHECK(found.stable());
  }
  options.block = 1;
  options.krylov_dimension = 60;
  products = 0;
  const FloquetMultipliers small = leading_floquet_multipliers(apply, n, options);
  measured("crowded multipliers, 60 vectors: residual", small.residual);
  measured("crowded multipliers, 60 vectors: products", static_cast<double>(products));
  CHECK_FALSE(small.converged);
}

TEST_CASE("Arnoldi reports every multiplier in a band round the unit circle, or says it did not",
          "[orbits]") {
  // A = S D S⁻¹ of size 400 with a crowd against the circle, μ_k = (1 − 4e-5 k²) e^{±0.03 k i}
  // for k = 1 .. 100, the other 200 in a disc of radius 0.5. Asked for six with a margin of 0.01
  // (the band |μ| > 0.99 holds the 15 pairs k <= 15), Arnoldi must double its count until the
  // band is covered and report all 30; with a margin of 0.2 (70 pairs) half its basis of 200 does
  // not reach below the band, and it must say so. With five pairs pushed outside the circle and
  // no margin, all ten outside must be reported (the continuation's rule for its stability).
  const Index n = 400;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto crowd = [&](double outside_scale) {
    Matrix D = Matrix::Zero(n, n);
    std::vector<Complex> all;
    for (int k = 1; k <= 100; ++k) {
      const double r = (1.0 - 4e-5 * k * k) * (k <= 5 ? outside_scale : 1.0), phi = 0.03 * k;
      put_pair(D, 2 * (k - 1), r, phi);
      all.push_back(std::polar(r, phi));
      all.push_back(std::polar(r, -phi));
    }
    for (Index i = 200; i + 1 < n; i += 2) put_pair(D, i, 0.5 * std::abs(u(rng)), 3.2 * u(rng));
    return std::make_pair(similar_to(D, rng), all);
  };
  const auto in_band = [](const std::vector<Complex>& values, double edge) {
    std::vector<Complex> out;
    for (const Complex& mu : values) {
      if (std::abs(mu) > edge) out.push_back(mu);
    }
    return out;
  };
  // Every value of `wanted` has one within 1e-9 among `found`.
  const auto all_found = [](const std::vector<Complex>& wanted, const std::vector<Complex>& found) {
    double worst = 0.0;
    for (const Complex& w : wanted) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Complex& f : found) nearest = std::min(nearest, std::abs(f - w));
      worst = std::max(worst, nearest);
    }
    return worst;
  };
  ArnoldiOptions options;
  options.count = 6;
  // Arnoldi on A with the margin: converged, every value of A's band (`count` of them) among
  // those reported to 1e-9, the smallest reported below the band. The farthest distance.
  const auto covered = [&](const Matrix& A, const std::vector<Complex>& all, double margin,
                           std::size_t count, FloquetMultipliers* out) {
    options.margin = margin;
    const FloquetMultipliers found =
        leading_floquet_multipliers([&A](Matrix& v) { v = A * v; }, n, options);
    const std::vector<Complex> wanted = in_band(all, 1.0 - margin);
    REQUIRE(wanted.size() == count);
    CHECK(found.converged);
    CHECK(found.band_covered);
    CHECK(found.values.size() >= count);
    CHECK(std::abs(found.values.back()) <= 1.0 - margin);
    *out = found;
    return all_found(wanted, found.values);
  };
  FloquetMultipliers found;
  {
    const auto [A, all] = crowd(1.0);
    const double worst = covered(A, all, 0.01, 30, &found);
    measured("band of 0.01: farthest multiplier of the band from a reported one", worst);
    CHECK(worst <= 1e-9);

    options.margin = 0.2;
    const FloquetMultipliers wide =
        leading_floquet_multipliers([&A](Matrix& v) { v = A * v; }, n, options);
    REQUIRE(in_band(all, 0.8).size() == 140);
    CHECK_FALSE(wide.band_covered);
    CHECK(wide.values.size() < 140);
    CHECK(std::abs(wide.values.back()) > 0.8);
  }
  const auto [A, all] = crowd(1.01);
  CHECK(covered(A, all, 0.0, 10, &found) <= 1e-9);
  CHECK(found.unstable_count() == 10);
}

TEST_CASE("on an operator its basis spans, Arnoldi reports the whole band at once", "[orbits]") {
  // Size 40 with a basis of 200: one cycle spans the space and every Ritz value is exact. Twelve
  // multipliers lie outside the circle (six pairs), another pair on it at e^{±3.1415 i}, and the
  // rest inside a disc of 0.5: asked for six with a margin of 1e-3, all fourteen of the band must
  // be reported and the band said to be covered (a basis that spans the operator cannot grow).
  const Index n = 40;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix D = Matrix::Zero(n, n);
  std::vector<Complex> band;
  for (int k = 0; k < 6; ++k) {
    const double r = 1.05 + 0.1 * k, phi = 0.4 + 0.45 * k;
    put_pair(D, 2 * k, r, phi);
    band.push_back(std::polar(r, phi));
    band.push_back(std::polar(r, -phi));
  }
  put_pair(D, 12, 1.0, 3.1415);
  band.push_back(std::polar(1.0, 3.1415));
  band.push_back(std::polar(1.0, -3.1415));
  for (Index i = 14; i + 1 < n; i += 2) put_pair(D, i, 0.5 * std::abs(u(rng)), 3.2 * u(rng));
  const Matrix A = similar_to(D, rng);
  ArnoldiOptions options;
  options.count = 6;
  options.margin = 1e-3;
  const FloquetMultipliers found =
      leading_floquet_multipliers([&A](Matrix& v) { v = A * v; }, n, options);
  CHECK(found.converged);
  CHECK(found.band_covered);
  REQUIRE(found.values.size() >= band.size());
  double worst = 0.0;
  for (const Complex& w : band) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Complex& f : found.values) nearest = std::min(nearest, std::abs(f - w));
    worst = std::max(worst, nearest);
  }
  measured("spanning basis: farthest multiplier of the band from a reported one", worst);
  CHECK(worst <= 1e-9);
  CHECK(std::abs(found.values.back()) <= 1.0 - options.margin);
}

TEST_CASE(
    "restarted Arnoldi finds the leading eigenvalues of a matrix built with them (orbit "
    "multipliers)",
    "[orbits]") {
  // A = S D S⁻¹, S a random well-conditioned basis, D with 2x2 rotation-scaling blocks for the
  // complex pairs. The leading six: 0.98 e^{±0.4i}, −0.96, 0.93 e^{±2.2i}, 0.9; the other 194 lie
  // in a disc of radius 0.8.
  const Index n = 200;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix D = Matrix::Zero(n, n);
  std::vector<Complex> expected;
  put_pair(D, 0, 0.98, 0.4);
  D(2, 2) = -0.96;
  put_pair(D, 3, 0.93, 2.2);
  D(5, 5) = 0.9;
  expected = {std::polar(0.98, 0.4), std::polar(0.98, -0.4), Complex(-0.96, 0),
              std::polar(0.93, 2.2), std::polar(0.93, -2.2), Complex(0.9, 0)};
  for (Index i = 6; i + 1 < n; i += 2) put_pair(D, i, 0.8 * std::abs(u(rng)), 3.2 * u(rng));
  const Matrix A = similar_to(D, rng);
  long products = 0;
  const auto apply = [&](Matrix& v) {
    products += v.cols();
    v = A * v;
  };

  ArnoldiOptions options;
  options.count = 6;
  options.krylov_dimension = 20;
  options.tolerance = 1e-12;
  options.max_restarts = 0;
  const FloquetMultipliers once = leading_floquet_multipliers(apply, n, options);
  measured("Arnoldi without restarts: residual", once.residual);
  CHECK(once.residual > 1e-12);  // 20 vectors are not enough ...
  options.max_restarts = 60;
  // The same by blocks of 2 columns a product.
  for (const int block : {2}) {
    INFO("block " << block);
    ArnoldiOptions blocked = options;
    blocked.block = block;
    const FloquetMultipliers by_blocks = leading_floquet_multipliers(apply, n, blocked);
    measured("restarted block Krylov-Schur: residual", by_blocks.residual);
    CHECK(by_blocks.residual <= 1e-12);
    CHECK(set_distance(expected, by_blocks.values) <= 1e-10);
  }
  products = 0;
  const FloquetMultipliers restarted = leading_floquet_multipliers(apply, n, options);
  measured("restarted Arnoldi: residual", restarted.residual);
  measured("restarted Arnoldi: products", static_cast<double>(products));
  CHECK(restarted.residual <= 1e-12);  // ... restarts are
  CHECK_FALSE(restarted.complete);
  const double distance = set_distance(expected, restarted.values);
  measured("restarted Arnoldi eigenvalue error", distance);
  CHECK(distance <= 1e-10);
  // Sorted: largest modulus first, the pair's positive imaginary part first.
  REQUIRE(restarted.values.size() == 6);
  CHECK(restarted.values[0].imag() > 0);
  CHECK(restarted.values[2].real() == Approx(-0.96).epsilon(1e-10));
  CHECK(restarted.largest_modulus() == Approx(0.98).epsilon(1e-10));
  // Every eigenvalue of a 6x6 matrix: complete, and exactly those of the dense solver.
  const Matrix small = A.topLeftCorner(6, 6);
  options.max_restarts = 5;
  const FloquetMultipliers all =
      leading_floquet_multipliers([&](Matrix& v) { v = small * v; }, 6, options);
  CHECK(all.complete);
  CHECK(set_distance(floquet_multipliers(small).values, all.values) <= 1e-12);
  // Blocks near the operator's size, 10x10: a basis of 8 and blocks of 2 fill the space exactly;
  // a basis of 10 leaves no room for a block beside it (single columns then, as plain Arnoldi
  // ends on the whole space). Both give the leading four of the dense solver.
  const Matrix ten = A.topLeftCorner(10, 10);
  const std::vector<Complex> dense_ten = floquet_multipliers(ten).values;
  for (const auto& [dimension, block, width] : {std::tuple{8, 2, 2}, std::tuple{10, 3, 1}}) {
    INFO("basis " << dimension << ", block " << block);
    ArnoldiOptions near_size = options;
    near_size.count = 4;
    near_size.krylov_dimension = dimension;
    near_size.block = block;
    near_size.max_restarts = 60;
    long wrong_width = 0;
    const FloquetMultipliers leading_four = leading_floquet_multipliers(
        [&](Matrix& v) {
          if (v.cols() != width) ++wrong_width;
          v = ten * v;
        },
        10, near_size);
    CHECK(wrong_width == 0);
    REQUIRE(leading_four.values.size() >= 4);
    CHECK(leading_four.converged);
    CHECK(set_distance(std::vector<Complex>(dense_ten.begin(), dense_ten.begin() + 4),
                       std::vector<Complex>(leading_four.values.begin(),
                                            leading_four.values.begin() + 4)) <= 1e-11);
  }
}

TEST_CASE("a product of several columns is split over two integrators, bit for bit", "[orbits]") {
  // From 1000 state components (500 masses) on, the banded switching PIM's map applies the second
  // half of a several-column product on a second integrator, in parallel: every column must come
  // out as the single-column product of a fresh map (integrated, not replayed) and as the same
  // product on one thread, to the last bit; and Arnoldi by blocks of two on that map must find
  // the leading multipliers plain Arnoldi finds.
  const NondimensionalChain chain = contact_chain(500);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(2);  // the split, even on a one-core machine
  StroboscopicMap map = banded_switching_map(chain), fresh = banded_switching_map(chain);
  CHECK(map.tangent_block() == 2);
  CHECK(banded_switching_map(contact_chain(499)).tangent_block() == 1);
  const Vector y = map.advance(pwl::test::harmonic_response(map.structure(), chain.theta), 3);
  Matrix V(map.state_size(), 3);
  for (Index i = 0; i < V.rows(); ++i) {
    V(i, 0) = std::sin(0.3 + 0.9 * static_cast<double>(i));
    V(i, 1) = std::cos(1.1 + 0.4 * static_cast<double>(i));
    V(i, 2) = std::sin(2.0 + 0.05 * static_cast<double>(i));
  }
  Matrix split = V;
  const Vector end = map.advance(y, 1, split);
  for (Index c = 0; c < V.cols(); ++c) {
    Matrix column = V.col(c);
    const Vector fresh_end = fresh.advance(y + 1e-3 * Vector::Ones(y.size()), 1);  // another arc
    CHECK(fresh_end.allFinite());
    fresh.advance(y, 1, column);  // integrated again (the last arc was another)
    CHECK((column.col(0) - split.col(c)).cwiseAbs().maxCoeff() == 0.0);
  }
  omp_set_num_threads(1);
  Matrix serial = V;
  CHECK((map.advance(y, 1, serial) - end).cwiseAbs().maxCoeff() == 0.0);
  CHECK((serial - split).cwiseAbs().maxCoeff() == 0.0);
  CHECK(split.cwiseAbs().maxCoeff() > 0.1);
  omp_set_num_threads(2);

  ArnoldiOptions plain;
  plain.count = 6;
  ArnoldiOptions blocks = plain;
  blocks.block = map.tangent_block();
  const auto apply = [&](Matrix& v) { map.advance(y, 1, v); };
  const FloquetMultipliers one = leading_floquet_multipliers(apply, map.state_size(), plain);
  const FloquetMultipliers two = leading_floquet_multipliers(apply, map.state_size(), blocks);
  CHECK(one.converged);
  CHECK(two.converged);
  const double distance = set_distance(one.values, two.values);
  measured("500 masses: Arnoldi by blocks of two against plain Arnoldi", distance);
  CHECK(distance <= 1e-9);
  omp_set_num_threads(threads);
}
