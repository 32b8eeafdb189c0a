// Substructure exponentials: He, Gao & Zhong, "An efficient numerical method for computing dynamic
// responses of periodic piecewise linear systems", Appl. Math. Mech. 39(7) (2018) 737-749, §2
// (figure 3: a substructure with its outside held fixed has the rows of the whole structure's
// exponential, because energy does not reach its cut within a step); the exponential itself by
// the precise integration method of Zhong & Williams (1994).
#include "pwl/numerics/substructure_exponential.hpp"

#include "numerics/row_blocks.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {
namespace {

void check_window(const GapStructure& s, Index first, Index last) {
  if (first < 0 || last > s.dofs() || first >= last) {
    throw InputError(fmt::format("substructure [{}, {}) must be a non-empty range inside 0..{}",
                                 first, last, s.dofs()));
  }
}

Matrix principal_block(const SparseMatrix& A, Index first, Index last) {
  const Index w = last - first;
  Matrix B = Matrix::Zero(w, w);
  for (Index j = first; j < last; ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      if (it.row() >= first && it.row() < last) B(it.row() - first, j - first) = it.value();
    }
  }
  return B;
}

}  // namespace

namespace banded_detail {

bool shifted_column_matches(const SparseMatrix& A, Index j, Index p) {
  SparseMatrix::InnerIterator a(A, j), b(A, j + p);
  for (; a && b; ++a, ++b) {
    if (a.row() + p != b.row() || a.value() != b.value()) return false;
  }
  return !a && !b;
}

}  // namespace banded_detail

SubstructureKey::SubstructureKey(const GapStructure& structure, Index first, Index last,
                                 const std::vector<LoadGroup>& loads) {
  check_window(structure, first, last);
  content_.reserve(static_cast<std::size_t>(4 + 16 * (last - first) +
                                            loads.size() * static_cast<std::size_t>(2 + 2 * (last - first))));
  content_.push_back(static_cast<double>(last - first));
  for (const SparseMatrix* A : {&structure.mass, &structure.damping, &structure.stiffness}) {
    content_.push_back(-1.0);  // separates the matrices
    for (Index j = first; j < last; ++j) {
      for (SparseMatrix::InnerIterator it(*A, j); it; ++it) {
        if (it.row() < first || it.row() >= last || it.value() == 0.0) continue;
        content_.push_back(static_cast<double>((it.row() - first) * (last - first) + j - first));
        content_.push_back(it.value());
      }
    }
  }
  for (const LoadGroup& g : loads) {
    content_.push_back(-2.0);
    content_.push_back(g.omega);
    for (const Vector* part : {&g.sin_part, &g.cos_part}) {
      if (part->size() != structure.dofs()) {
        throw InputError(fmt::format("a load group has {} entries for {} degrees of freedom",
                                     part->size(), structure.dofs()));
      }
      for (Index i = first; i < last; ++i) content_.push_back((*part)[i]);
    }
  }
  std::uint64_t h = 1469598103934665603ULL;
  for (double v : content_) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 1099511628211ULL;
    h ^= h >> 29;
  }
  hash_ = static_cast<std::size_t>(h);
}

Matrix substructure_state_matrix(const GapStructure& structure, Index first, Index last) {
  check_window(structure, first, last);
  const Index w = last - first;
  const Matrix M = principal_block(structure.mass, first, last);
  const Eigen::LLT<Matrix> mass(M);
  if (mass.info() != Eigen::Success) {
    throw InputError(fmt::format("the mass matrix of substructure [{}, {}) is not positive "
                                 "definite",
                                 first, last));
  }
  Matrix H = Matrix::Zero(2 * w, 2 * w);
  H.topRightCorner(w, w).setIdentity();
  H.bottomLeftCorner(w, w) = -mass.solve(principal_block(structure.stiffness, first, last));
  H.bottomRightCorner(w, w) = -mass.solve(principal_block(structure.damping, first, last));
  return H;
}

SubstructureExponential substructure_exponential(const GapStructure& structure, Index first,
                                                 Index last, double step,
                                                 const std::vector<LoadGroup>& loads,
                                                 const PreciseExponentialOptions& options) {
  check_window(structure, first, last);
  const Index w = last - first;
  const Index h = static_cast<Index>(loads.size());
  const Matrix H = substructure_state_matrix(structure, first, last);
  const Eigen::LLT<Matrix> mass(principal_block(structure.mass, first, last));
  // Unit accelerations at every degree of freedom: the columns of [0; I].
  Matrix G = Matrix::Zero(2 * w, w);
  G.bottomRows(w).setIdentity();
  // Each group's sine and cosine parts as accelerations [0; M⁻¹ f].
  Matrix B = Matrix::Zero(2 * w, 2 * h);
  Vector frequencies(2 * h);
  for (Index g = 0; g < h; ++g) {
    const LoadGroup& group = loads[static_cast<std::size_t>(g)];
    if (group.sin_part.size() != structure.dofs() || group.cos_part.size() != structure.dofs()) {
      throw InputError(fmt::format("load group {} has {} and {} entries for {} degrees of freedom",
                                   g, group.sin_part.size(), group.cos_part.size(),
                                   structure.dofs()));
    }
    B.col(2 * g).bottomRows(w) = mass.solve(group.sin_part.segment(first, w));
    B.col(2 * g + 1).bottomRows(w) = mass.solve(group.cos_part.segment(first, w));
    frequencies[2 * g] = frequencies[2 * g + 1] = group.omega;
  }
  PreciseExponential e = precise_exponential(H, step, G, B, frequencies, options);

  SubstructureExponential out;
  out.first = first;
  out.size = w;
  out.transition = std::move(e.transition);
  out.falling_load = e.gamma1 / step;
  out.rising_load = e.gamma0 - out.falling_load;
  // As in pim_step_operators.cpp: ∫ e^{H(η-s)} b sin(ω(t_k+s)) ds = Im(e^{iωt_k} Kω b), and the
  // cosine load is the real part.
  for (Index g = 0; g < h; ++g) {
    HarmonicResponse r;
    r.omega = loads[static_cast<std::size_t>(g)].omega;
    r.sin_response = e.harmonic_real.col(2 * g) - e.harmonic_imag.col(2 * g + 1);
    r.cos_response = e.harmonic_imag.col(2 * g) + e.harmonic_real.col(2 * g + 1);
    out.harmonics.push_back(std::move(r));
  }
  return out;
}

Index detect_cell_size(const GapStructure& structure, Index max_cell) {
  const Index n = structure.dofs();
  const Index lo = n / 4;
  for (Index p = 1; p <= max_cell; ++p) {
    const Index hi = n - n / 4 - p;
    if (hi - lo < 2 * p) break;  // too short to tell
    bool periodic = true;
    for (const SparseMatrix* A : {&structure.mass, &structure.damping, &structure.stiffness}) {
      for (Index j = lo; j < hi && periodic; ++j) {
        periodic = banded_detail::shifted_column_matches(*A, j, p);
      }
      if (!periodic) break;
    }
    if (periodic) return p;
  }
  return 0;
}

namespace banded_detail {

// The windows that repeat, by the same column comparison as detect_cell_size (row_blocks.hpp).
CellRepeats::CellRepeats(const GapStructure& s, Index cell, const std::vector<LoadGroup>& loads) {
  const Index n = s.dofs();
  const auto fill = [&](Index shift) {
    differing_.assign(static_cast<std::size_t>(n + 1), 0);
    for (Index i = 0; i < n; ++i) {
      bool repeats = i >= shift;
      for (const SparseMatrix* A : {&s.mass, &s.damping, &s.stiffness}) {
        repeats = repeats && shifted_column_matches(*A, i - shift, shift);
      }
      for (const LoadGroup& g : loads) {
        repeats = repeats && g.sin_part[i] == g.sin_part[i - shift] &&
                  g.cos_part[i] == g.cos_part[i - shift];
      }
      differing_[static_cast<std::size_t>(i + 1)] =
          differing_[static_cast<std::size_t>(i)] + (repeats ? 0 : 1);
    }
  };
  if (cell <= 0) return;  // no cell: nothing repeats
  const Index lo = n / 4, hi = n - n / 4;
  for (Index k = 1; k <= 8; ++k) {
    shift_ = k * cell;
    if (hi - lo < 2 * shift_) break;
    fill(shift_);
    if (differing_[static_cast<std::size_t>(hi)] == differing_[static_cast<std::size_t>(lo + shift_)]) {
      return;
    }
  }
  shift_ = cell;
  fill(shift_);
}

}  // namespace banded_detail

}  // namespace pwl
