#include "pwl/model/gap_structure.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/SparseCholesky>
#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {
namespace {

// Checks that a matrix is n x n with finite entries and, when asked, symmetric. Returns false and
// names the matrix and the offending entry.
bool check_matrix(const SparseMatrix& A, const char* name, Index n, std::string* why) {
  if (A.rows() != n || A.cols() != n) {
    *why = fmt::format("{} is {}x{}, expected {}x{} (the mass matrix's size)", name, A.rows(),
                       A.cols(), n, n);
    return false;
  }
  double largest = 0.0;
  for (Index j = 0; j < A.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      if (!std::isfinite(it.value())) {
        *why = fmt::format("{}[{},{}] = {} is not finite", name, it.row(), it.col(), it.value());
        return false;
      }
      largest = std::max(largest, std::abs(it.value()));
    }
  }
  // Each off-diagonal entry against its mirror, found by a search in the mirror's column: no
  // transpose is formed.
  for (Index j = 0; j < A.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      if (it.row() == j) continue;
      if (std::abs(it.value() - A.coeff(j, it.row())) > 1e-12 * std::max(1.0, largest)) {
        *why = fmt::format("{} is not symmetric: {}[{},{}] = {} but {}[{},{}] = {}", name, name,
                           it.row(), it.col(), A.coeff(it.row(), it.col()), name, it.col(),
                           it.row(), A.coeff(it.col(), it.row()));
        return false;
      }
    }
  }
  return true;
}

// Up to this bandwidth the LDL^T below keeps the natural order.
constexpr Index kNaturalOrderBandwidth = 64;

// Whether a symmetric matrix is positive (semi)definite, by a sparse LDL^T. A semidefinite
// check allows pivots down to -tol * scale (a free-free stiffness matrix has zero pivots).
bool check_definite(const SparseMatrix& A, const char* name, const char* quantity, bool strict,
                    std::string* why) {
  for (Index i = 0; i < A.rows(); ++i) {
    const double d = A.coeff(i, i);
    if (strict ? d <= 0.0 : d < 0.0) {
      *why = fmt::format("{}[{},{}] = {}: {} must be {}", name, i, i, d, quantity,
                         strict ? "positive" : "non-negative");
      return false;
    }
  }
  if (A.nonZeros() == 0) {
    if (strict) *why = fmt::format("{} is zero: {} must be positive", name, quantity);
    return !strict;
  }
  // A chain's matrices are narrow bands, which the natural order factorises without fill: the
  // fill-reducing ordering (AMD) would cost more than the factorisation itself.
  Index bandwidth = 0;
  for (Index j = 0; j < A.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      bandwidth = std::max<Index>(bandwidth, std::abs(it.row() - j));
    }
  }
  // The pivots of B's LDL^T; false when the factorisation stops (a zero pivot).
  const auto pivots = [&](const SparseMatrix& B, Vector& d) {
    const auto factor = [&](auto& ldlt) {
      ldlt.compute(B);
      if (ldlt.info() != Eigen::Success) return false;
      d = ldlt.vectorD();
      return true;
    };
    if (bandwidth <= kNaturalOrderBandwidth) {
      Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt;
      return factor(ldlt);
    }
    Eigen::SimplicialLDLT<SparseMatrix> ldlt;
    return factor(ldlt);
  };
  Vector d;
  if (!pivots(A, d)) {
    if (strict) {
      *why = fmt::format("{} is not positive definite (its factorisation failed)", name);
      return false;
    }
    // A singular semidefinite matrix (a free-free stiffness) stops the factorisation at a zero
    // pivot. Shifted by a small multiple of its largest entry it is definite; an indefinite one
    // (whose negative eigenvalue is larger than the shift) is not.
    const double largest = A.coeffs().cwiseAbs().maxCoeff();
    if (largest == 0.0) return true;  // zeros stored explicitly: the zero matrix
    const double shift = 1e-10 * largest;
    SparseMatrix shifted = A;
    for (Index i = 0; i < A.rows(); ++i) shifted.coeffRef(i, i) += shift;
    if (!pivots(shifted, d) || !(d.minCoeff() > 0.0)) {
      *why = fmt::format("{} is not positive semidefinite: its LDL^T stops at a zero pivot, and "
                         "shifted by {:.3g} I it is still not definite",
                         name, shift);
      return false;
    }
    return true;
  }
  const double scale = std::max(1e-300, d.cwiseAbs().maxCoeff());
  for (Index i = 0; i < d.size(); ++i) {
    if (strict ? d[i] <= 1e-14 * scale : d[i] < -1e-10 * scale) {
      *why = fmt::format("{} is not positive {}definite: pivot {} of its LDL^T is {}", name,
                         strict ? "" : "semi", i, d[i]);
      return false;
    }
  }
  return true;
}

}  // namespace

bool GapStructure::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  const Index n = mass.rows();
  if (n <= 0) {
    *why = fmt::format("mass has {} rows: a structure needs at least one degree of freedom", n);
    return false;
  }
  if (!check_matrix(mass, "mass", n, why) || !check_matrix(damping, "damping", n, why) ||
      !check_matrix(stiffness, "stiffness", n, why)) {
    return false;
  }
  if (!check_definite(mass, "mass", "a mass", true, why) ||
      !check_definite(damping, "damping", "a damping coefficient", false, why) ||
      !check_definite(stiffness, "stiffness", "a stiffness", false, why)) {
    return false;
  }
  for (std::size_t j = 0; j < springs.size(); ++j) {
    const GapSpring& s = springs[j];
    if (s.dof < 0 || s.dof >= n) {
      *why = fmt::format("springs[{}].dof = {} is outside 0..{}", j, s.dof, n - 1);
      return false;
    }
    if (s.other_dof < -1 || s.other_dof >= n || s.other_dof == s.dof) {
      *why = fmt::format("springs[{}].other_dof = {} must be -1 (ground) or another dof in 0..{}",
                         j, s.other_dof, n - 1);
      return false;
    }
    if (s.direction != 1.0 && s.direction != -1.0) {
      *why = fmt::format("springs[{}].direction = {} must be +1 or -1", j, s.direction);
      return false;
    }
    if (!std::isfinite(s.stiffness) || s.stiffness < 0.0) {
      *why = fmt::format("springs[{}].stiffness = {} must be finite and non-negative", j,
                         s.stiffness);
      return false;
    }
    if (!std::isfinite(s.gap)) {
      *why = fmt::format("springs[{}].gap = {} is not finite", j, s.gap);
      return false;
    }
  }
  for (std::size_t j = 0; j < loads.size(); ++j) {
    const HarmonicLoad& l = loads[j];
    if (l.dof < 0 || l.dof >= n) {
      *why = fmt::format("loads[{}].dof = {} is outside 0..{}", j, l.dof, n - 1);
      return false;
    }
    if (!std::isfinite(l.amplitude)) {
      *why = fmt::format("loads[{}].amplitude = {} is not finite", j, l.amplitude);
      return false;
    }
    if (!std::isfinite(l.omega) || l.omega < 0.0) {
      *why = fmt::format("loads[{}].omega = {} must be finite and non-negative", j, l.omega);
      return false;
    }
    if (!std::isfinite(l.phase)) {
      *why = fmt::format("loads[{}].phase = {} is not finite", j, l.phase);
      return false;
    }
  }
  return true;
}

void GapStructure::validate() const {
  std::string why;
  if (!is_valid(&why)) throw InputError("invalid structure: " + why);
}

Matrix GapStructure::spring_directions() const { return Matrix(spring_directions_sparse()); }

SparseMatrix GapStructure::spring_directions_sparse() const {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(2 * springs.size());
  for (std::size_t j = 0; j < springs.size(); ++j) {
    const GapSpring& s = springs[j];
    entries.emplace_back(s.dof, static_cast<Index>(j), s.direction);
    if (s.other_dof >= 0) entries.emplace_back(s.other_dof, static_cast<Index>(j), -s.direction);
  }
  SparseMatrix W(dofs(), spring_count());
  W.setFromTriplets(entries.begin(), entries.end());
  return W;
}

Vector GapStructure::spring_gaps() const {
  Vector gaps(spring_count());
  for (Index j = 0; j < gaps.size(); ++j) gaps[j] = springs[static_cast<std::size_t>(j)].gap;
  return gaps;
}

Vector GapStructure::spring_stiffnesses() const {
  Vector k(spring_count());
  for (Index j = 0; j < k.size(); ++j) k[j] = springs[static_cast<std::size_t>(j)].stiffness;
  return k;
}

Vector GapStructure::gap_functions(const Eigen::Ref<const Vector>& x) const {
  Vector g(spring_count());
  for (Index j = 0; j < g.size(); ++j) {
    const GapSpring& s = springs[static_cast<std::size_t>(j)];
    const double relative = x[s.dof] - (s.other_dof >= 0 ? x[s.other_dof] : 0.0);
    g[j] = s.direction * relative - s.gap;
  }
  return g;
}

Vector GapStructure::spring_forces(const Eigen::Ref<const Vector>& x) const {
  Vector p = gap_functions(x);
  for (Index j = 0; j < p.size(); ++j) {
    p[j] = springs[static_cast<std::size_t>(j)].stiffness * std::max(0.0, p[j]);
  }
  return p;
}

Vector GapStructure::load(double t) const {
  Vector f = Vector::Zero(dofs());
  for (const HarmonicLoad& l : loads) f[l.dof] += l.amplitude * std::sin(l.omega * t + l.phase);
  return f;
}

std::vector<LoadGroup> GapStructure::load_groups() const {
  std::vector<LoadGroup> groups;
  for (const HarmonicLoad& l : loads) {
    auto same = std::find_if(groups.begin(), groups.end(), [&](const LoadGroup& g) {
      return std::abs(g.omega - l.omega) <= 1e-12 * std::max(g.omega, l.omega);
    });
    if (same == groups.end()) {
      groups.push_back({l.omega, Vector::Zero(dofs()), Vector::Zero(dofs())});
      same = groups.end() - 1;
    }
    // A sin(ωt + φ) = A cos φ sin ωt + A sin φ cos ωt
    same->sin_part[l.dof] += l.amplitude * std::cos(l.phase);
    same->cos_part[l.dof] += l.amplitude * std::sin(l.phase);
  }
  return groups;
}

double GapStructure::common_period(int max_denominator, double rel_tol) const {
  std::vector<double> omegas;
  for (const LoadGroup& g : load_groups()) {
    if (g.omega > 0.0 && (g.sin_part.squaredNorm() > 0.0 || g.cos_part.squaredNorm() > 0.0)) {
      omegas.push_back(g.omega);
    }
  }
  if (omegas.empty()) {
    throw InputError("common_period: the structure has no time-varying load (every omega is 0)");
  }
  // Each ω_i = ω_0 p_i / q_i with small integers; the common period is 2π q / ω_0 with
  // q chosen so that every ratio becomes a whole multiple of the base frequency ω_0 / q.
  const double base = omegas.front();
  long long common_denominator = 1;
  std::vector<std::pair<long long, long long>> ratios;
  for (double w : omegas) {
    const double r = w / base;
    bool found = false;
    for (long long q = 1; q <= max_denominator && !found; ++q) {
      const double p = std::round(r * static_cast<double>(q));
      if (p >= 1.0 && std::abs(p / static_cast<double>(q) - r) <= rel_tol * r) {
        ratios.emplace_back(static_cast<long long>(p), q);
        common_denominator = std::lcm(common_denominator, q);
        found = true;
      }
    }
    if (!found) {
      throw InputError(fmt::format(
          "common_period: load frequencies {} and {} are incommensurate (no ratio p/q with q <= "
          "{} within relative {})",
          base, w, max_denominator, rel_tol));
    }
  }
  // Fundamental frequency: gcd of the integer multiples of base / common_denominator.
  long long g = 0;
  for (auto [p, q] : ratios) g = std::gcd(g, p * (common_denominator / q));
  const double fundamental = base * static_cast<double>(g) / static_cast<double>(common_denominator);
  return 2.0 * M_PI / fundamental;
}

double GapStructure::scale() const {
  double s = 0.0;
  for (const SparseMatrix* A : {&mass, &damping, &stiffness}) {
    for (Index j = 0; j < A->outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(*A, j); it; ++it) s = std::max(s, std::abs(it.value()));
    }
  }
  return s;
}

SparseMatrix to_sparse(const Matrix& dense) { return dense.sparseView(); }

}  // namespace pwl
