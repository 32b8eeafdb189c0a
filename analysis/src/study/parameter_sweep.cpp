#include "pwl/study/parameter_sweep.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

std::string doubles(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{:.17g}", i ? "," : "", v[i]);
  return s;
}

std::string number(double v) { return std::isnan(v) ? std::string() : fmt::format("{:.17g}", v); }

}  // namespace

std::string component_name(int component, int masses) {
  return component < masses ? fmt::format("x{}", component + 1)
                            : fmt::format("v{}", component - masses + 1);
}

bool SweepOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (points < 1) {
    *why = fmt::format("points = {} must be at least 1", points);
    return false;
  }
  if (!std::isfinite(from) || !std::isfinite(to)) {
    *why = fmt::format("range [{}, {}] must be finite", from, to);
    return false;
  }
  if (points > 1 && !(from < to)) {
    *why = fmt::format("range [{}, {}] is reversed or empty: give from < to (a continuation runs "
                       "both directions by itself)",
                       from, to);
    return false;
  }
  if (mode == SweepMode::continuation && !upward && !downward) {
    *why = "a continuation needs the upward or the downward branch (or both)";
    return false;
  }
  if (!point.is_valid(chain.masses, why)) return false;
  if (initial_state.size() != 0 && initial_state.size() != 2 * chain.masses) {
    *why = fmt::format("initial state has {} entries, expected {}", initial_state.size(),
                       2 * chain.masses);
    return false;
  }
  // Every value must give a valid chain (θ > 0, α >= 0, ...): check the two ends.
  for (double v : {from, to}) {
    try {
      make_chain(with_parameter(chain, parameter, v));
    } catch (const InputError& e) {
      *why = fmt::format("{} = {}: {}", parameter_name(parameter), v, e.what());
      return false;
    }
    if (parameter == SweepParameter::theta && !(v > 0.0)) {
      *why = fmt::format("theta = {} must be positive", v);
      return false;
    }
  }
  return true;
}

double SweepOptions::value(int index) const {
  if (points == 1) return from;
  return from + (to - from) * static_cast<double>(index) / static_cast<double>(points - 1);
}

std::vector<GridTask> SweepOptions::tasks() const {
  std::vector<GridTask> result;
  if (mode == SweepMode::independent) {
    for (int i = 0; i < points; ++i) result.push_back({{i}, false});
    return result;
  }
  if (upward) {
    GridTask up{{}, true};
    for (int i = 0; i < points; ++i) up.ids.push_back(i);
    result.push_back(std::move(up));
  }
  if (downward) {
    GridTask down{{}, true};
    for (int i = points - 1; i >= 0; --i) down.ids.push_back(points + i);
    result.push_back(std::move(down));
  }
  return result;
}

NondimensionalChain SweepOptions::chain_of(long id) const {
  return with_parameter(chain, parameter, value(static_cast<int>(id % points)));
}

Vector SweepOptions::start_state() const {
  return initial_state.size() != 0 ? initial_state : Vector::Zero(2 * chain.masses);
}

std::string SweepOptions::describe() const {
  std::string s;
  s += "study = sweep\n";
  s += fmt::format("masses = {}\nalpha = {}\nzeta = {:.17g}\ngap = {}\ntheta = {:.17g}\n"
                   "amplitude = {}\n",
                   chain.masses, doubles(chain.alpha), chain.zeta, doubles(chain.gap), chain.theta,
                   doubles(chain.amplitude));
  s += fmt::format("parameter = {}\nfrom = {:.17g}\nto = {:.17g}\npoints = {}\n",
                   parameter_name(parameter), from, to, points);
  s += fmt::format("mode = {}\n", mode == SweepMode::independent ? "independent" : "continuation");
  if (mode == SweepMode::continuation) {
    s += fmt::format("upward = {}\ndownward = {}\n", upward, downward);
  }
  std::vector<double> start(static_cast<std::size_t>(start_state().size()));
  for (std::size_t i = 0; i < start.size(); ++i) start[i] = start_state()[static_cast<Index>(i)];
  s += fmt::format("initial_state = {}\n", doubles(start));
  s += fmt::format("transient_periods = {}\nrecorded_periods = {}\nsteps_per_period = {}\n",
                   point.transient_periods, point.recorded_periods, point.steps_per_period);
  s += fmt::format("components = {}\nobservable = {}\nlyapunov = {}\nmethod = {}\n",
                   fmt::join(point.components, ","), point.observable, point.lyapunov,
                   point.method);
  if (point.method != "pim") s += fmt::format("tolerance = {:.17g}\n", point.tolerance);
  return s;
}

void write_sweep_files(const SweepOptions& o, const std::map<long, PointResult>& records,
                       const std::string& folder) {
  const std::string poincare_path = folder + "/poincare.csv";
  const std::string classes_path = folder + "/classification.csv";
  std::FILE* poincare = std::fopen(poincare_path.c_str(), "w");
  std::FILE* classes = std::fopen(classes_path.c_str(), "w");
  if (poincare == nullptr || classes == nullptr) {
    if (poincare) std::fclose(poincare);
    if (classes) std::fclose(classes);
    throw Error(fmt::format("cannot write {} and {}", poincare_path, classes_path));
  }
  const std::string name = parameter_name(o.parameter);
  fmt::print(poincare, "{},direction,index,period_index", name);
  for (int c : o.point.components) fmt::print(poincare, ",{}", component_name(c, o.chain.masses));
  fmt::print(poincare, "\n");
  fmt::print(classes, "index,{},direction,regime,code,period,lambda1,lambda1_error,K\n", name);
  // std::map iterates in id order: up (0..N-1) then down (N..2N-1), each by index.
  for (const auto& [id, r] : records) {
    const int index = static_cast<int>(id % o.points);
    const char* direction = id < o.points ? "up" : "down";
    const double value = o.value(index);
    fmt::print(classes, "{},{:.17g},{},{},{},{},{},{},{}\n", index, value, direction,
               r.regime.empty() ? "failed" : r.regime, regime_code(r.regime, r.period), r.period,
               number(r.lambda1), number(r.lambda1_error), number(r.K));
    const int rows = r.rows();
    for (int k = 0; k < rows; ++k) {
      fmt::print(poincare, "{:.17g},{},{},{}", value, direction, index,
                 o.point.transient_periods + k + 1);
      for (int c = 0; c < r.columns; ++c) {
        fmt::print(poincare, ",{:.17g}",
                   r.poincare[static_cast<std::size_t>(k) * static_cast<std::size_t>(r.columns) +
                              static_cast<std::size_t>(c)]);
      }
      fmt::print(poincare, "\n");
    }
  }
  const bool ok = std::fclose(poincare) == 0;
  if (std::fclose(classes) != 0 || !ok) {
    throw Error(fmt::format("cannot finish writing {} and {}", poincare_path, classes_path));
  }
}

}  // namespace pwl::analysis
