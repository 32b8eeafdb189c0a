#include "bench/bench_reference.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

// d'Alembert: the acceleration of `dof` from the equation of motion at (t, x, x'):
// M x'' = f(t) - C x' - K x - W P(x), with a diagonal mass.
double acceleration(const GapStructure& s, const std::vector<int>& springs, Index dof, double t,
                    const Vector& x, const Vector& v) {
  double f = 0.0;
  for (const HarmonicLoad& l : s.loads) {
    if (l.dof == dof) f += l.amplitude * std::sin(l.omega * t + l.phase);
  }
  // C and K are symmetric: column dof is row dof.
  for (SparseMatrix::InnerIterator it(s.damping, dof); it; ++it) f -= it.value() * v[it.row()];
  for (SparseMatrix::InnerIterator it(s.stiffness, dof); it; ++it) f -= it.value() * x[it.row()];
  for (int j : springs) {
    const GapSpring& sp = s.springs[static_cast<std::size_t>(j)];
    const double rel = x[sp.dof] - (sp.other_dof >= 0 ? x[sp.other_dof] : 0.0);
    const double force = sp.stiffness * std::max(0.0, sp.direction * rel - sp.gap);
    const double w = sp.dof == dof ? sp.direction : -sp.direction;  // W(dof, j)
    f -= w * force;
  }
  return f / s.mass.coeff(dof, dof);
}

}  // namespace

ReferenceTrack ReferenceTrack::compute(const GapStructure& structure, double t_end,
                                       const MethodSettings& settings, double grid, Index dof) {
  if (!(grid > 0.0) || !(t_end > 0.0)) {
    throw InputError(fmt::format("reference track: grid = {} and t_end = {} must be positive",
                                 grid, t_end));
  }
  if (!locates_switches(settings)) {
    throw InputError(fmt::format("reference track: {} does not end a step at every spring switch",
                                 method_label(settings)));
  }
  std::vector<int> springs;
  for (std::size_t j = 0; j < structure.springs.size(); ++j) {
    if (structure.springs[j].dof == dof || structure.springs[j].other_dof == dof) {
      springs.push_back(static_cast<int>(j));
    }
  }
  ReferenceTrack track;
  auto integrator = make_integrator(structure, settings);
  const Vector rest = Vector::Zero(structure.dofs());
  integrator->set_state(0.0, rest, rest);
  const auto record = [&](double t, const Vector& x, const Vector& v) {
    if (!track.t_.empty() && !(t > track.t_.back())) return;
    track.t_.push_back(t);
    track.x_.push_back(x[dof]);
    track.v_.push_back(v[dof]);
    track.a_.push_back(acceleration(structure, springs, dof, t, x, v));
  };
  record(0.0, rest, rest);
  const auto start = std::chrono::steady_clock::now();
  const long points = static_cast<long>(std::ceil(t_end / grid - 1e-9));
  for (long k = 1; k <= points; ++k) {
    integrator->advance_to(std::min(t_end, static_cast<double>(k) * grid), record);
  }
  track.seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return track;
}

double ReferenceTrack::interpolate(double t, int derivative) const {
  if (t_.size() < 2 || t < t_.front() || t > t_.back() * (1 + 1e-14)) {
    throw InputError(fmt::format("reference track: t = {} is outside [0, {}]", t, t_end()));
  }
  std::size_t k = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
  k = std::clamp<std::size_t>(k, 1, t_.size() - 1);
  const std::size_t i = k - 1;
  const double h = t_[k] - t_[i];
  const double s = std::clamp((t - t_[i]) / h, 0.0, 1.0);
  const double s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
  const double p0 = x_[i], d0 = h * v_[i], c0 = h * h * a_[i];
  const double p1 = x_[k], d1 = h * v_[k], c1 = h * h * a_[k];
  if (derivative == 0) {
    return p0 * (1 - 10 * s3 + 15 * s4 - 6 * s5) + d0 * (s - 6 * s3 + 8 * s4 - 3 * s5) +
           c0 * 0.5 * (s2 - 3 * s3 + 3 * s4 - s5) + p1 * (10 * s3 - 15 * s4 + 6 * s5) +
           d1 * (-4 * s3 + 7 * s4 - 3 * s5) + c1 * 0.5 * (s3 - 2 * s4 + s5);
  }
  if (h < 1e-4) {
    // Events can sit a few nanoseconds apart; there x1 - x0 is all rounding, and x' is better
    // interpolated from x' and x'' at the ends (cubic Hermite, error O(h^4)).
    const double q0 = v_[i], q1 = v_[k], e0 = h * a_[i], e1 = h * a_[k];
    return q0 * (1 - 3 * s2 + 2 * s3) + e0 * (s - 2 * s2 + s3) + q1 * (3 * s2 - 2 * s3) +
           e1 * (s3 - s2);
  }
  const double dp = p0 * (-30 * s2 + 60 * s3 - 30 * s4) + d0 * (1 - 18 * s2 + 32 * s3 - 15 * s4) +
                    c0 * 0.5 * (2 * s - 9 * s2 + 12 * s3 - 5 * s4) +
                    p1 * (30 * s2 - 60 * s3 + 30 * s4) + d1 * (-12 * s2 + 28 * s3 - 15 * s4) +
                    c1 * 0.5 * (3 * s2 - 8 * s3 + 5 * s4);
  return dp / h;
}

double ReferenceTrack::position(double t) const { return interpolate(t, 0); }
double ReferenceTrack::velocity(double t) const { return interpolate(t, 1); }

std::pair<double, double> ReferenceTrack::difference(const ReferenceTrack& other) const {
  double dx = 0.0, dv = 0.0;
  for (std::size_t i = 0; i < t_.size(); ++i) {
    if (t_[i] > other.t_end()) break;
    dx = std::max(dx, std::abs(x_[i] - other.position(t_[i])));
    dv = std::max(dv, std::abs(v_[i] - other.velocity(t_[i])));
  }
  return {dx, dv};
}

void ReferenceTrack::save(const std::string& path, const std::string& label) const {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", path));
  fmt::print(f, "# {}\nt,x,v,a\n", label);
  for (std::size_t i = 0; i < t_.size(); ++i) {
    fmt::print(f, "{:.17g},{:.17g},{:.17g},{:.17g}\n", t_[i], x_[i], v_[i], a_[i]);
  }
  std::fclose(f);
}

bool ReferenceTrack::load(const std::string& path, const std::string& label) {
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line) || line != "# " + label || !std::getline(in, line)) {
    return false;
  }
  t_.clear();
  x_.clear();
  v_.clear();
  a_.clear();
  while (std::getline(in, line)) {
    double t, x, v, a;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &t, &x, &v, &a) != 4) return false;
    t_.push_back(t);
    x_.push_back(x);
    v_.push_back(v);
    a_.push_back(a);
  }
  return t_.size() >= 2;
}

std::pair<double, double> largest_errors(const TrackRecord& record,
                                         const ReferenceTrack& reference) {
  double ex = 0.0, ev = 0.0;
  for (std::size_t i = 0; i < record.t.size(); ++i) {
    ex = std::max(ex, std::abs(record.x[i] - reference.position(record.t[i])));
    ev = std::max(ev, std::abs(record.v[i] - reference.velocity(record.t[i])));
  }
  return {ex, ev};
}

}  // namespace pwl::app
