#include "pwl/model/chain_builders.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {
namespace {

// A per-mass value: one entry means "the same for every mass".
double per_mass(const std::vector<double>& values, int i, int n, const char* field) {
  if (values.size() == 1) return values[0];
  if (values.size() == static_cast<std::size_t>(n)) return values[static_cast<std::size_t>(i)];
  throw InputError(fmt::format("{} has {} values; give 1 (for every mass) or {} (one per mass)",
                               field, values.size(), n));
}

void check_masses(int n) {
  if (n < 1) throw InputError(fmt::format("masses = {} must be at least 1", n));
}

}  // namespace

SparseMatrix fixed_free_laplacian(Index n) {
  std::vector<Eigen::Triplet<double>> entries;
  for (Index i = 0; i < n; ++i) {
    entries.emplace_back(i, i, i + 1 < n ? 2.0 : 1.0);
    if (i + 1 < n) {
      entries.emplace_back(i, i + 1, -1.0);
      entries.emplace_back(i + 1, i, -1.0);
    }
  }
  SparseMatrix L(n, n);
  L.setFromTriplets(entries.begin(), entries.end());
  return L;
}

GapStructure make_chain(const ChainParameters& p) {
  check_masses(p.masses);
  const int n = p.masses;
  std::vector<Eigen::Triplet<double>> m, c, k;
  // Element i joins mass i-1 (or the wall, for i = 0) to mass i.
  for (int i = 0; i < n; ++i) {
    const double mi = per_mass(p.mass, i, n, "mass");
    const double ki = per_mass(p.k1, i, n, "k1");
    const double ci = per_mass(p.damping, i, n, "damping");
    if (!std::isfinite(mi) || mi <= 0.0) {
      throw InputError(fmt::format("mass[{}] = {} must be positive and finite", i, mi));
    }
    if (!std::isfinite(ki) || ki < 0.0) {
      throw InputError(fmt::format("k1[{}] = {} must be non-negative and finite", i, ki));
    }
    if (!std::isfinite(ci) || ci < 0.0) {
      throw InputError(fmt::format("damping[{}] = {} must be non-negative and finite", i, ci));
    }
    m.emplace_back(i, i, mi);
    for (auto [list, value] : {std::pair{&k, ki}, std::pair{&c, ci}}) {
      list->emplace_back(i, i, value);
      if (i > 0) {
        list->emplace_back(i - 1, i - 1, value);
        list->emplace_back(i - 1, i, -value);
        list->emplace_back(i, i - 1, -value);
      }
    }
  }
  GapStructure s;
  s.mass.resize(n, n);
  s.damping.resize(n, n);
  s.stiffness.resize(n, n);
  s.mass.setFromTriplets(m.begin(), m.end());
  s.damping.setFromTriplets(c.begin(), c.end());
  s.stiffness.setFromTriplets(k.begin(), k.end());
  for (int i = 0; i < n; ++i) {
    s.springs.push_back({i, -1, 1.0, per_mass(p.k2, i, n, "k2"), per_mass(p.gap, i, n, "gap")});
  }
  s.loads = p.loads;
  s.validate();
  return s;
}

ChainParameters paper_large_chain(int masses) {
  check_masses(masses);
  ChainParameters p;
  p.masses = masses;
  for (int i = 0; i < masses; ++i) {
    // 1-based odd masses are 0-based even indices.
    if (i % 2 == 0) {
      p.loads.push_back({i, 1.0, 3.0, 0.0});
    } else {
      p.loads.push_back({i, -2.0, 5.0, 0.0});
    }
  }
  return p;
}

double NondimensionalChain::period() const { return 2.0 * M_PI / theta; }

GapStructure make_chain(const NondimensionalChain& p) {
  check_masses(p.masses);
  if (!std::isfinite(p.theta) || p.theta <= 0.0) {
    throw InputError(fmt::format("theta = {} must be positive and finite", p.theta));
  }
  if (!std::isfinite(p.zeta) || p.zeta < 0.0) {
    throw InputError(fmt::format("zeta = {} must be non-negative and finite", p.zeta));
  }
  ChainParameters c;
  c.masses = p.masses;
  c.mass = {1.0};
  c.k1 = {1.0};
  c.damping = {p.zeta};
  c.k2.resize(static_cast<std::size_t>(p.masses));
  c.gap.resize(static_cast<std::size_t>(p.masses));
  for (int i = 0; i < p.masses; ++i) {
    const double a = per_mass(p.alpha, i, p.masses, "alpha");
    if (!std::isfinite(a) || a < 0.0) {
      throw InputError(fmt::format("alpha[{}] = {} must be non-negative and finite", i, a));
    }
    c.k2[static_cast<std::size_t>(i)] = a;
    c.gap[static_cast<std::size_t>(i)] = per_mass(p.gap, i, p.masses, "gap");
    const double q = per_mass(p.amplitude, i, p.masses, "amplitude");
    if (!std::isfinite(q)) throw InputError(fmt::format("amplitude[{}] = {} is not finite", i, q));
    if (q != 0.0) c.loads.push_back({i, q, p.theta, 0.0});
  }
  return make_chain(c);
}

NondimensionalChain paper_five_dof_case(const std::string& figure) {
  NondimensionalChain c;  // n = 5, ζ = 0.2, Q = (1, -1, 1, -1, 1)
  if (figure == "4a") {
    c.alpha = {2.0}; c.gap = {0.0}; c.theta = 1.0;
  } else if (figure == "4b") {
    c.alpha = {8.0}; c.gap = {0.1}; c.theta = 1.0;
  } else if (figure == "5") {
    c.alpha = {5.0}; c.gap = {0.0}; c.theta = 2.0;
  } else if (figure == "6") {
    c.alpha = {15.0}; c.gap = {0.0}; c.theta = 1.5;
  } else {
    throw InputError(fmt::format("figure = \"{}\": the paper's 5-DOF cases are 4a, 4b, 5 and 6",
                                 figure));
  }
  return c;
}

}  // namespace pwl
