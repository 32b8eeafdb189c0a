// Lyapunov exponents by the QR method (Shimada & Nagashima 1979; Benettin, Galgani, Giorgilli &
// Strelcyn 1980) and by two nearby trajectories (Benettin, Galgani & Strelcyn 1976).
#include "pwl/analysis/lyapunov.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

bool fail(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

// Checks shared by both option structs.
bool common_valid(const char* type, long iterations, long transient, double time_per_iteration,
                  int blocks, double divergence_bound, std::string* why) {
  if (blocks < 2) return fail(why, fmt::format("{}.blocks = {} must be >= 2", type, blocks));
  if (iterations < blocks) {
    return fail(why, fmt::format("{}.iterations = {} must be >= blocks ({})", type, iterations,
                                 blocks));
  }
  if (transient < 0) return fail(why, fmt::format("{}.transient = {} must be >= 0", type, transient));
  if (!(time_per_iteration > 0.0) || !std::isfinite(time_per_iteration)) {
    return fail(why, fmt::format("{}.time_per_iteration = {} must be finite and > 0", type,
                                 time_per_iteration));
  }
  if (!(divergence_bound > 0.0)) {
    return fail(why, fmt::format("{}.divergence_bound = {} must be > 0", type, divergence_bound));
  }
  return true;
}

void check_initial_state(const Vector& x0) {
  if (x0.size() == 0) throw InputError("x0: the initial state is empty (size 0)");
  for (Index i = 0; i < x0.size(); ++i) {
    if (!std::isfinite(x0[i])) throw InputError(fmt::format("x0[{}] = {} is not finite", i, x0[i]));
  }
}

void check_state(const Vector& x, Index dim, long iteration, double bound, const char* what) {
  if (x.size() != dim) {
    throw InputError(fmt::format("map: returned a state of size {} at iteration {}, expected {}",
                                 x.size(), iteration, dim));
  }
  for (Index i = 0; i < dim; ++i) {
    if (!std::isfinite(x[i]) || std::abs(x[i]) > bound) {
      throw DivergenceError(fmt::format("{}[{}] = {} after iteration {} is beyond the divergence "
                                        "bound {}",
                                        what, i, x[i], iteration, bound));
    }
  }
}

void check_jacobian(const Matrix& J, Index dim, long iteration) {
  if (J.rows() != dim || J.cols() != dim) {
    throw InputError(fmt::format("jacobian at iteration {} is {}x{}, expected {}x{}", iteration,
                                 J.rows(), J.cols(), dim, dim));
  }
  if (!J.allFinite()) {
    throw InputError(fmt::format("jacobian at iteration {} has a non-finite entry", iteration));
  }
}

// Uniform in [-1, 1) from the raw 64-bit output, so the same seed gives the same numbers with
// every standard library (the std distributions are implementation-defined).
double uniform_symmetric(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-52 - 1.0;
}

// Averages of log growth rates over a window split into batches.
class RateAverager {
 public:
  RateAverager(Index rates, long iterations, int blocks)
      : iterations_(iterations),
        blocks_(blocks),
        stride_(std::max(1L, iterations / kCheckpoints)),
        total_(Vector::Zero(rates)),
        second_half_(Vector::Zero(rates)),
        block_sums_(Matrix::Zero(rates, blocks)) {
    checkpoints_.emplace_back(0, total_);
  }

  // Adds the logs of iteration n (0-based within the window).
  void add(long n, const Vector& logs) {
    total_ += logs;
    if (n >= iterations_ / 2) second_half_ += logs;
    block_sums_.col(block_of(n)) += logs;
    if ((n + 1) % stride_ == 0 || n + 1 == iterations_) checkpoints_.emplace_back(n + 1, total_);
  }

  LyapunovResult finish(double time_per_iteration) const {
    const Index p = total_.size();
    LyapunovResult result;
    result.iterations = iterations_;
    result.time_per_iteration = time_per_iteration;
    result.per_iteration = total_ / static_cast<double>(iterations_);
    result.per_unit_time = result.per_iteration / time_per_iteration;
    result.standard_error.resize(p);
    result.half_difference.resize(p);
    result.range_error.resize(p);
    result.error.resize(p);
    const long half_count = iterations_ - iterations_ / 2;
    for (Index i = 0; i < p; ++i) {
      if (!std::isfinite(result.per_iteration[i])) {
        // A superstable iteration made this rate exactly -infinity: nothing to estimate.
        result.standard_error[i] = result.half_difference[i] = result.range_error[i] = 0.0;
        result.error[i] = 0.0;
        continue;
      }
      Vector means(blocks_);
      for (int b = 0; b < blocks_; ++b) means[b] = block_sums_(i, b) / block_length(b);
      const double mean = means.mean();
      const double variance = (means.array() - mean).square().sum() / (blocks_ - 1);
      result.standard_error[i] = std::sqrt(variance / blocks_);
      result.half_difference[i] =
          std::abs(second_half_[i] / static_cast<double>(half_count) - result.per_iteration[i]);
      // The bridge S(n) - n λ: its range bounds how far any partial average strays.
      double low = 0.0;
      double high = 0.0;
      for (const auto& [n, sums] : checkpoints_) {
        const double bridge = sums[i] - static_cast<double>(n) * result.per_iteration[i];
        low = std::min(low, bridge);
        high = std::max(high, bridge);
      }
      result.range_error[i] = (high - low) / static_cast<double>(iterations_);
      result.error[i] = std::max(
          {result.standard_error[i], result.half_difference[i], result.range_error[i]});
    }
    return result;
  }

 private:
  // Block b covers [b N / B, (b + 1) N / B), so the lengths differ by at most one.
  long block_start(int b) const { return b * iterations_ / blocks_; }
  double block_length(int b) const {
    return static_cast<double>(block_start(b + 1) - block_start(b));
  }
  int block_of(long n) const {
    int b = static_cast<int>(n * blocks_ / iterations_);
    while (b + 1 < blocks_ && n >= block_start(b + 1)) ++b;
    while (b > 0 && n < block_start(b)) --b;
    return b;
  }

  // The running sums are kept at about this many evenly spaced iterations, so that memory does
  // not grow with the window.
  static constexpr long kCheckpoints = 4096;

  long iterations_;
  int blocks_;
  long stride_;
  std::vector<std::pair<long, Vector>> checkpoints_;  // (iterations so far, sums of logs)
  Vector total_;
  Vector second_half_;
  Matrix block_sums_;
};

// The orthonormal frame of the QR method.
class Frame {
 public:
  Frame(Index dim, Index p, std::uint64_t seed) : q_(dim, p), logs_(p) {
    std::mt19937_64 rng(seed);
    Matrix start(dim, p);
    for (Index j = 0; j < p; ++j) {
      for (Index i = 0; i < dim; ++i) start(i, j) = uniform_symmetric(rng);
    }
    Eigen::HouseholderQR<Matrix> qr(start);
    q_.setIdentity();
    q_.applyOnTheLeft(qr.householderQ());
  }

  // Q <- orthonormal factor of J Q; returns ln |R(i, i)|.
  const Vector& push(const Matrix& J) {
    qr_.compute(J * q_);
    const auto& packed = qr_.matrixQR();
    for (Index i = 0; i < logs_.size(); ++i) logs_[i] = std::log(std::abs(packed(i, i)));
    q_.setIdentity();
    q_.applyOnTheLeft(qr_.householderQ());
    return logs_;
  }

 private:
  Matrix q_;
  Vector logs_;
  Eigen::HouseholderQR<Matrix> qr_;
};

Index exponent_count(const LyapunovOptions& options, Index dim) {
  if (options.exponents > dim) {
    throw InputError(fmt::format("LyapunovOptions.exponents = {} exceeds the dimension {}",
                                 options.exponents, dim));
  }
  return options.exponents == 0 ? dim : options.exponents;
}

void validate(const LyapunovOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
}

}  // namespace

bool LyapunovOptions::is_valid(std::string* why) const {
  if (exponents < 0) {
    return fail(why, fmt::format("LyapunovOptions.exponents = {} must be >= 0", exponents));
  }
  return common_valid("LyapunovOptions", iterations, transient, time_per_iteration, blocks,
                      divergence_bound, why);
}

bool TwoTrajectoryOptions::is_valid(std::string* why) const {
  if (!(separation > 0.0) || !std::isfinite(separation)) {
    return fail(why, fmt::format("TwoTrajectoryOptions.separation = {} must be finite and > 0",
                                 separation));
  }
  return common_valid("TwoTrajectoryOptions", iterations, transient, time_per_iteration, blocks,
                      divergence_bound, why);
}

LyapunovResult lyapunov_spectrum(const TangentMap& map, const Vector& x0,
                                 const LyapunovOptions& options) {
  validate(options);
  if (!map) throw InputError("map: the map is empty (no callable)");
  check_initial_state(x0);
  const Index dim = x0.size();
  const Index p = exponent_count(options, dim);

  Frame frame(dim, p, options.seed);
  RateAverager averager(p, options.iterations, options.blocks);
  Vector x = x0;
  Matrix J(dim, dim);
  const long total = options.transient + options.iterations;
  for (long n = 0; n < total; ++n) {
    J.setConstant(std::numeric_limits<double>::quiet_NaN());  // a map that forgets J is caught
    Vector next = map(x, &J);
    check_state(next, dim, n + 1, options.divergence_bound, "x");
    check_jacobian(J, dim, n);
    const Vector& logs = frame.push(J);
    if (n >= options.transient) averager.add(n - options.transient, logs);
    x = std::move(next);
  }
  LyapunovResult result = averager.finish(options.time_per_iteration);
  result.final_state = std::move(x);
  return result;
}

LyapunovResult lyapunov_spectrum(const std::vector<Matrix>& jacobians,
                                 const LyapunovOptions& options) {
  validate(options);
  const long total = options.transient + options.iterations;
  if (static_cast<long>(jacobians.size()) < total) {
    throw InputError(fmt::format("jacobians: {} given, fewer than transient + iterations = {}",
                                 jacobians.size(), total));
  }
  const Index dim = jacobians.front().rows();
  if (dim == 0) throw InputError("jacobians[0]: empty matrix (0x0)");
  const Index p = exponent_count(options, dim);

  Frame frame(dim, p, options.seed);
  RateAverager averager(p, options.iterations, options.blocks);
  for (long n = 0; n < total; ++n) {
    check_jacobian(jacobians[n], dim, n);
    const Vector& logs = frame.push(jacobians[n]);
    if (n >= options.transient) averager.add(n - options.transient, logs);
  }
  return averager.finish(options.time_per_iteration);
}

LyapunovResult largest_lyapunov_two_trajectories(const StateMap& map, const Vector& x0,
                                                 const TwoTrajectoryOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (!map) throw InputError("map: the map is empty (no callable)");
  check_initial_state(x0);
  const Index dim = x0.size();

  std::mt19937_64 rng(options.seed);
  Vector direction(dim);
  for (Index i = 0; i < dim; ++i) direction[i] = uniform_symmetric(rng);
  direction.normalize();

  const double d0 = options.separation;
  RateAverager averager(1, options.iterations, options.blocks);
  Vector x = x0;
  Vector y = x0 + d0 * direction;
  Vector logs(1);
  const long total = options.transient + options.iterations;
  for (long n = 0; n < total; ++n) {
    Vector x_next = map(x);
    Vector y_next = map(y);
    check_state(x_next, dim, n + 1, options.divergence_bound, "x");
    check_state(y_next, dim, n + 1, options.divergence_bound, "companion x");
    const Vector separation = y_next - x_next;
    const double d = separation.norm();
    if (!(d > 0.0)) {
      throw DivergenceError(fmt::format("the two trajectories coincided at iteration {} "
                                        "(separation {}): increase separation",
                                        n + 1, d));
    }
    logs[0] = std::log(d / d0);
    if (n >= options.transient) averager.add(n - options.transient, logs);
    x = std::move(x_next);
    // Reset to distance d0 along the direction the map has stretched the separation into, which
    // converges to the most expanding one.
    y = x + (d0 / d) * separation;
  }
  LyapunovResult result = averager.finish(options.time_per_iteration);
  result.final_state = std::move(x);
  return result;
}

}  // namespace pwl::analysis
