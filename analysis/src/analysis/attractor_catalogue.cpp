#include "pwl/analysis/attractor_catalogue.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pwl/errors.hpp"

namespace pwl::analysis {

bool AttractorMatchOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (!(periodic_tolerance > 0.0) || !std::isfinite(periodic_tolerance)) {
    *why = fmt::format("periodic_tolerance = {} must be positive and finite", periodic_tolerance);
    return false;
  }
  if (!(cloud_factor > 0.0) || !std::isfinite(cloud_factor)) {
    *why = fmt::format("cloud_factor = {} must be positive and finite", cloud_factor);
    return false;
  }
  return true;
}

bool is_periodic_regime(const std::string& regime) {
  return regime.rfind("period-", 0) == 0 || regime == "equilibrium";
}

bool is_bounded_aperiodic_regime(const std::string& regime) {
  return regime == "quasi-periodic" || regime == "chaotic" || regime == "uncertain";
}

namespace {

// The last `k` rows of `points` (k <= rows).
Matrix last_rows(const Matrix& points, Index k) { return points.bottomRows(k); }

// Squared distance from row i of a to its nearest row of b (skipping row i itself when `self`).
double nearest_squared(const Matrix& a, Index i, const Matrix& b, bool self) {
  double best = std::numeric_limits<double>::infinity();
  for (Index j = 0; j < b.rows(); ++j) {
    if (self && j == i) continue;
    best = std::min(best, (a.row(i) - b.row(j)).squaredNorm());
  }
  return best;
}

double median(std::vector<double> values) {
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  return values[mid];
}

// Median nearest-neighbour distance from the rows of a to those of b (within a when `self`).
double median_nearest(const Matrix& a, const Matrix& b, bool self) {
  std::vector<double> d;
  d.reserve(static_cast<std::size_t>(a.rows()));
  for (Index i = 0; i < a.rows(); ++i) d.push_back(std::sqrt(nearest_squared(a, i, b, self)));
  return median(std::move(d));
}

int period_of(const MotionTail& m) { return m.regime == "equilibrium" ? 1 : m.period; }

}  // namespace

AttractorCatalogue::AttractorCatalogue(const AttractorMatchOptions& options) : options_(options) {
  std::string why;
  if (!options_.is_valid(&why)) throw InputError("attractor matching: " + why);
}

const Attractor& AttractorCatalogue::attractor(int id) const {
  if (id < 1 || id > static_cast<int>(attractors_.size())) {
    throw InputError(fmt::format("attractor {} does not exist (there are {})", id,
                                 attractors_.size()));
  }
  return attractors_[static_cast<std::size_t>(id - 1)];
}

bool AttractorCatalogue::same_orbit(const Attractor& a, const MotionTail& m) const {
  if (!is_periodic_regime(a.regime) || a.period != period_of(m)) return false;
  const Matrix orbit = last_rows(a.points, a.period);
  const Matrix mine = last_rows(m.points, a.period);
  double largest = 0.0, diameter = 0.0;
  for (Index i = 0; i < orbit.rows(); ++i) {
    largest = std::max(largest, orbit.row(i).norm());
    for (Index j = 0; j < i; ++j) diameter = std::max(diameter, (orbit.row(i) - orbit.row(j)).norm());
  }
  const double scale = std::max({diameter, largest, std::numeric_limits<double>::min()});
  const double limit = options_.periodic_tolerance * scale;
  for (Index i = 0; i < mine.rows(); ++i) {
    if (std::sqrt(nearest_squared(mine, i, orbit, false)) > limit) return false;
  }
  return true;
}

bool AttractorCatalogue::same_cloud(const Attractor& a, const MotionTail& m) const {
  if (!is_bounded_aperiodic_regime(a.regime)) return false;
  const double spacing =
      std::max(median_nearest(a.points, a.points, true), median_nearest(m.points, m.points, true));
  const double limit = options_.cloud_factor * spacing;
  return median_nearest(m.points, a.points, false) <= limit &&
         median_nearest(a.points, m.points, false) <= limit;
}

int AttractorCatalogue::match(const MotionTail& m, long tag) {
  if (m.regime == "failed") return 0;
  const bool unbounded = m.regime == "unbounded";
  const bool periodic = is_periodic_regime(m.regime);
  if (!unbounded) {
    if (!periodic && !is_bounded_aperiodic_regime(m.regime)) {
      throw InputError(fmt::format("attractor matching: unknown regime '{}'", m.regime));
    }
    const Index needed = periodic ? period_of(m) : 2;
    if (needed < 1 || m.points.rows() < needed) {
      throw InputError(fmt::format(
          "attractor matching: a {} motion needs at least {} points of its tail; {} given",
          m.regime, std::max<Index>(needed, 1), m.points.rows()));
    }
    if (width_ < 0) width_ = m.points.cols();
    if (m.points.cols() != width_) {
      throw InputError(fmt::format("attractor matching: a tail of {} columns among tails of {}",
                                   m.points.cols(), width_));
    }
  }
  for (Attractor& a : attractors_) {
    const bool same = unbounded ? a.regime == "unbounded"
                      : periodic ? same_orbit(a, m)
                                 : same_cloud(a, m);
    if (same) {
      ++a.motions;
      return a.id;
    }
  }
  Attractor found;
  found.id = static_cast<int>(attractors_.size()) + 1;
  found.regime = m.regime;
  found.period = periodic ? period_of(m) : 0;
  if (!unbounded) found.points = m.points;
  found.motions = 1;
  found.first = tag;
  attractors_.push_back(std::move(found));
  return attractors_.back().id;
}

}  // namespace pwl::analysis
