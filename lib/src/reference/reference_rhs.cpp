#include "reference/reference_rhs.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "pwl/errors.hpp"

namespace pwl::reference_detail {
namespace {

// Up to this size a coupled M is factored densely: its O(n^2) triangular solves beat the
// bookkeeping of a sparse factor. Beyond it a sparse factor keeps a banded M at O(n) per call.
constexpr Index kDenseMassLimit = 64;
// K and C are applied by diagonals when they have at most this many nonzero diagonals together
// and the diagonals are at least half full (otherwise the compressed rows do less work).
constexpr std::size_t kMaxDiagonals = 16;

// The nonzero diagonals of a square sparse matrix, as offset -> values by row.
std::map<Index, Vector> diagonals_of(const SparseMatrix& A) {
  std::map<Index, Vector> diagonals;
  for (Index j = 0; j < A.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      if (it.value() == 0.0) continue;
      auto [entry, inserted] = diagonals.try_emplace(it.col() - it.row());
      if (inserted) entry->second = Vector::Zero(A.rows());
      entry->second[it.row()] = it.value();
    }
  }
  return diagonals;
}

bool is_diagonal(const SparseMatrix& A) {
  for (Index j = 0; j < A.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      if (it.row() != it.col() && it.value() != 0.0) return false;
    }
  }
  return true;
}

}  // namespace

GapRhs::GapRhs(const GapStructure& structure) : n_(structure.dofs()), work_(structure.dofs()) {
  const Index n = n_;

  // [K C] so that K x + C x' is one sparse product with y = [x; x'].
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(structure.stiffness.nonZeros() +
                                           structure.damping.nonZeros()));
  for (Index j = 0; j < n; ++j) {
    for (SparseMatrix::InnerIterator it(structure.stiffness, j); it; ++it) {
      if (it.value() != 0.0) entries.emplace_back(it.row(), it.col(), it.value());
    }
    for (SparseMatrix::InnerIterator it(structure.damping, j); it; ++it) {
      if (it.value() != 0.0) entries.emplace_back(it.row(), n + it.col(), it.value());
    }
  }
  kc_.resize(n, 2 * n);
  kc_.setFromTriplets(entries.begin(), entries.end());
  kc_.makeCompressed();

  const std::map<Index, Vector> k_diagonals = diagonals_of(structure.stiffness);
  const std::map<Index, Vector> c_diagonals = diagonals_of(structure.damping);
  const std::size_t count = k_diagonals.size() + c_diagonals.size();
  if (count <= kMaxDiagonals &&
      static_cast<double>(kc_.nonZeros()) >= 0.5 * static_cast<double>(count) * n) {
    for (const auto& [diagonals, base] :
         {std::pair{&k_diagonals, Index{0}}, std::pair{&c_diagonals, n}}) {
      for (const auto& [offset, values] : *diagonals) {
        diagonals_.push_back({offset, base, std::max<Index>(0, -offset),
                              std::min<Index>(n, n - offset), values});
      }
    }
  }

  for (const GapSpring& s : structure.springs) {
    // A spring without stiffness exerts no force; it still has a gap function, so it stays in
    // the list (the kink-located integrators report its crossings like any other).
    springs_.push_back({s.dof, s.other_dof, s.direction, s.stiffness, s.gap});
  }

  for (const pwl::LoadGroup& group : structure.load_groups()) {
    LoadGroup g{group.omega, {}};
    for (Index i = 0; i < n; ++i) {
      if (group.sin_part[i] != 0.0 || group.cos_part[i] != 0.0) {
        g.terms.push_back({i, group.sin_part[i], group.cos_part[i]});
      }
    }
    if (!g.terms.empty()) loads_.push_back(std::move(g));
  }

  if (is_diagonal(structure.mass)) {
    mass_kind_ = MassKind::diagonal;
    inverse_mass_diagonal_ = structure.mass.diagonal().cwiseInverse();
  } else if (n <= kDenseMassLimit) {
    mass_kind_ = MassKind::dense;
    dense_mass_.compute(Matrix(structure.mass));
    if (dense_mass_.info() != Eigen::Success) {
      throw InputError("mass is not positive definite (its dense Cholesky factorisation failed)");
    }
  } else {
    mass_kind_ = MassKind::sparse;
    sparse_mass_ = std::make_unique<Eigen::SimplicialLLT<SparseMatrix>>(structure.mass);
    if (sparse_mass_->info() != Eigen::Success) {
      throw InputError("mass is not positive definite (its sparse Cholesky factorisation failed)");
    }
  }
}

const char* GapRhs::mass_treatment() const {
  switch (mass_kind_) {
    case MassKind::diagonal:
      return "diagonal";
    case MassKind::dense:
      return "dense";
    case MassKind::sparse:
      return "sparse";
  }
  return "unknown";
}

void GapRhs::evaluate(const Vector& y, Vector& dydt, double t) {
  ++evaluations_;
  const Index n = n_;
  const double* yd = y.data();
  double* out = dydt.data();
  double* acc = out + n;

  std::copy(yd + n, yd + 2 * n, out);  // x' = v

  // acc = -(K x + C v).
  if (!diagonals_.empty()) {
    std::fill(acc, acc + n, 0.0);
    for (const Diagonal& d : diagonals_) {
      const double* values = d.values.data();
      const double* source = yd + d.column_base + d.offset;
      for (Index i = d.first; i < d.last; ++i) acc[i] -= values[i] * source[i];
    }
  } else {
    const int* outer = kc_.outerIndexPtr();
    const int* inner = kc_.innerIndexPtr();
    const double* values = kc_.valuePtr();
    for (Index i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int p = outer[i]; p < outer[i + 1]; ++p) sum += values[p] * yd[inner[p]];
      acc[i] = -sum;
    }
  }

  for (const LoadGroup& g : loads_) {
    const double s = std::sin(g.omega * t);
    const double c = std::cos(g.omega * t);
    for (const LoadTerm& term : g.terms) {
      acc[term.dof] += term.sin_coefficient * s + term.cos_coefficient * c;
    }
  }

  // -W P with P_j = k_j max(0, g_j); column j of W is direction (e_dof - e_other).
  for (std::size_t j = 0; j < springs_.size(); ++j) {
    const Spring& s = springs_[j];
    const double relative = yd[s.dof] - (s.other >= 0 ? yd[s.other] : 0.0);
    const double g = s.direction * relative - s.gap;
    if (modes_ != nullptr ? modes_[j] > 0 : g > 0.0) {
      const double push = s.direction * s.stiffness * g;
      acc[s.dof] -= push;
      if (s.other >= 0) acc[s.other] += push;
    }
  }

  solve_mass(acc);
}

void GapRhs::solve_mass(double* rhs) {
  Eigen::Map<Vector> b(rhs, n_);
  switch (mass_kind_) {
    case MassKind::diagonal:
      b.array() *= inverse_mass_diagonal_.array();
      break;
    case MassKind::dense:
      dense_mass_.solveInPlace(b);
      break;
    case MassKind::sparse: {
      // M = P^T L L^T P, solved through the preallocated work vector (Eigen's solve() would
      // allocate a temporary on every call).
      work_.noalias() = sparse_mass_->permutationP() * b;
      sparse_mass_->matrixL().solveInPlace(work_);
      sparse_mass_->matrixU().solveInPlace(work_);
      b.noalias() = sparse_mass_->permutationPinv() * work_;
      break;
    }
  }
}

void GapRhs::gaps(const Vector& y, Vector& g) const {
  for (std::size_t j = 0; j < springs_.size(); ++j) {
    const Spring& s = springs_[j];
    const double relative = y[s.dof] - (s.other >= 0 ? y[s.other] : 0.0);
    g[static_cast<Index>(j)] = s.direction * relative - s.gap;
  }
}

void GapRhs::gap_directional(const Vector& y, Index offset, Vector& out) const {
  for (std::size_t j = 0; j < springs_.size(); ++j) {
    const Spring& s = springs_[j];
    const double relative = y[offset + s.dof] - (s.other >= 0 ? y[offset + s.other] : 0.0);
    out[static_cast<Index>(j)] = s.direction * relative;
  }
}

void GapRhs::gap_scales(const Vector& y, Vector& out) const {
  for (std::size_t j = 0; j < springs_.size(); ++j) {
    const Spring& s = springs_[j];
    const double relative = y[s.dof] - (s.other >= 0 ? y[s.other] : 0.0);
    out[static_cast<Index>(j)] = std::abs(relative) + std::abs(s.gap);
  }
}

}  // namespace pwl::reference_detail
