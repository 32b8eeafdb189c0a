// The 0-1 test for chaos: K near 1 for chaotic series and noise, near 0 for periodic and
// quasi-periodic ones; reproducible for a fixed seed.
#include "pwl/analysis/zero_one_test.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "pwl/errors.hpp"
#include "test_series.hpp"

using namespace pwl::analysis;
using Catch::Matchers::Contains;

namespace {

// Logistic-map values after a transient of 1000 from x = 0.1234 (test_series.hpp).
std::vector<double> logistic_series(double r, int count) {
  return pwl::test::logistic_series(r, count, 1000, 0.1234);
}

// An observable of the golden-mean rotation, with a harmonic so that it is not a pure cosine.
std::vector<double> golden_rotation_series(int count, double offset = 0.0) {
  const double alpha = 2.0 * std::numbers::pi * (std::sqrt(5.0) - 1.0) / 2.0;
  std::vector<double> values;
  for (int n = 0; n < count; ++n) {
    const double theta = 0.3 + n * alpha;
    values.push_back(offset + std::cos(theta) + 0.3 * std::cos(2.0 * theta));
  }
  return values;
}

}  // namespace

TEST_CASE("0-1 test: logistic map at r = 4 is chaotic", "[zero_one]") {
  const ZeroOneResult result = zero_one_test(logistic_series(4.0, 2000));
  CHECK(result.K > 0.9);
  // K is a correlation, at most 1 by construction; for the fully chaotic logistic map its known
  // limit is 1, and 2000 points with 100 frequencies reach it within 0.01 (0.998 here).
  CHECK(result.K == Approx(1.0).margin(0.01));
  CHECK_FALSE(result.constant_series);
  CHECK(result.lags == 200);
  REQUIRE(result.c.size() == 100);
  REQUIRE(result.K_c.size() == 100);
  for (double c : result.c) {
    CHECK(c > std::numbers::pi / 5.0);
    CHECK(c < 4.0 * std::numbers::pi / 5.0);
  }
}

TEST_CASE("0-1 test: golden-mean rotation is regular", "[zero_one]") {
  CHECK(zero_one_test(golden_rotation_series(2000)).K < 0.1);
  // A large mean would dominate M_c through the oscillatory term if it were not subtracted.
  CHECK(zero_one_test(golden_rotation_series(2000, 10.0)).K < 0.1);
}

TEST_CASE("0-1 test: periodic series are regular", "[zero_one]") {
  // Period 4: the walk resonates at c = pi/2, inside (pi/5, 4 pi/5); the median over c ignores it.
  const ZeroOneResult period4 = zero_one_test(logistic_series(3.5, 2000));
  CHECK(period4.K < 0.1);
  const auto resonant = std::count_if(period4.K_c.begin(), period4.K_c.end(),
                                      [](double k) { return k > 0.5; });
  CHECK(resonant < 50);
  CHECK(zero_one_test(logistic_series(3.2, 2000)).K < 0.1);
}

TEST_CASE("0-1 test: independent noise diffuses like chaos", "[zero_one]") {
  std::vector<double> noise;
  std::uint64_t state = 42;
  for (int n = 0; n < 2000; ++n) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;  // Knuth's MMIX LCG
    noise.push_back(static_cast<double>(state >> 11) * 0x1.0p-53);
  }
  CHECK(zero_one_test(noise).K > 0.9);
}

TEST_CASE("0-1 test: a constant series gives K = 0", "[zero_one]") {
  const ZeroOneResult result = zero_one_test(std::vector<double>(500, 0.7));
  CHECK(result.constant_series);
  CHECK(result.K == 0.0);
  // ... and so does one that varies only at rounding level around its mean.
  std::vector<double> almost(500, 0.7);
  almost[17] = std::nextafter(0.7, 1.0);
  CHECK(zero_one_test(almost).constant_series);
}

TEST_CASE("0-1 test: reproducible for a seed", "[zero_one]") {
  const std::vector<double> series = logistic_series(3.7, 1000);
  const ZeroOneResult a = zero_one_test(series);
  const ZeroOneResult b = zero_one_test(series);
  CHECK(a.c == b.c);
  CHECK(a.K == b.K);
  ZeroOneOptions other;
  other.seed = 7;
  const ZeroOneResult c = zero_one_test(series, other);
  CHECK(c.c != a.c);
  // r = 3.7 is chaotic (lambda ~ 0.35): both seeds say so.
  CHECK(a.K > 0.8);
  CHECK(c.K > 0.8);
}

TEST_CASE("0-1 test input errors name the field and the value", "[zero_one][errors]") {
  CHECK_THROWS_MATCHES(zero_one_test(std::vector<double>{}), pwl::InputError,
                       Catch::Matchers::Message(
                           "series: 0 samples, fewer than ZeroOneOptions.min_samples = 100"));
  std::vector<double> series = logistic_series(4.0, 200);
  series[5] = std::nan("");
  CHECK_THROWS_WITH(zero_one_test(series), Contains("series[5]") && Contains("nan"));
  series[5] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(zero_one_test(series), Contains("series[5]") && Contains("inf"));

  ZeroOneOptions options;
  options.c_max = 4.0;
  CHECK_THROWS_WITH(zero_one_test(logistic_series(4.0, 200), options), Contains("c_max = 4"));
  options = {};
  options.frequencies = 0;
  CHECK_THROWS_WITH(zero_one_test(logistic_series(4.0, 200), options), Contains("frequencies = 0"));
  options = {};
  options.lag_fraction = 0.9;
  std::string why;
  CHECK_FALSE(options.is_valid(&why));
  CHECK_THAT(why, Contains("lag_fraction = 0.9"));
}
