// The banded precise-integration step of He, Gao & Zhong, Appl. Math. Mech. 39(7) (2018)
// 737-749 (eqs 13 and 20-22), with the precise integration method of Zhong & Williams (1994).
#include "pwl/integrators/banded_propagator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "numerics/thread_rows.hpp"
#include "pwl/errors.hpp"
#include "pwl/numerics/state_checks.hpp"

namespace pwl {

namespace {

constexpr double kNotFinite = std::numeric_limits<double>::quiet_NaN();

double larger(double largest, double value) {
  const double m = std::abs(value);
  return m <= largest ? largest : m;  // a NaN replaces it, and stays
}

// y += A P for the acting forces (P zero elsewhere): by the rows of A when many act, by the
// columns of the acting ones otherwise. Returns max(largest, |y_i| over the rows it changed).
double add_forces_checked(const BandedMatrix& A, const BandedMatrix& columns, const Vector& P,
                          const std::vector<int>& acting, double* y, double largest) {
  if (4 * static_cast<Index>(acting.size()) > P.size()) {
    A.multiply_add(P.data(), y);
    for (Index r = 0; r < A.rows(); ++r) largest = larger(largest, y[r]);
  } else if (!acting.empty()) {
    columns.transpose_multiply_add(P.data(), acting.data(), static_cast<Index>(acting.size()), y);
    for (int j : acting) {
      const Index f = columns.first_column(j);
      for (Index k = 0; k < columns.width(); ++k) largest = larger(largest, y[f + k]);
    }
  }
  return largest;
}

}  // namespace

BandedPropagator::BandedPropagator(BandedStepOperators ops, const BandedLcpOptions& lcp,
                                   double divergence_bound)
    : ops_(std::move(ops)),
      solver_(lcp),
      n_(ops_.transition.rows() / 2),
      bound_(divergence_bound) {
  const Index m = ops_.lcp_matrix.rows();
  std::string why;
  if (m > 0 && !is_p_matrix(ops_.lcp_matrix, &why)) {
    throw InputError(fmt::format(
        "step = {}: the step's LCP matrix is not a P-matrix ({}), so the spring forces are not "
        "unique; use a smaller step",
        ops_.step, why));
  }
  if (m > 0) solver_.set_matrix(ops_.lcp_matrix);
  force_now_columns_ = transpose(ops_.force_now);
  force_next_columns_ = transpose(ops_.force_next);
  const Index groups = static_cast<Index>(ops_.harmonics.size());
  BandedMatrixBuilder h(2 * n_, 2 * groups, 2 * groups);
  std::vector<double> row(static_cast<std::size_t>(2 * groups));
  for (Index r = 0; r < 2 * n_; ++r) {
    for (Index g = 0; g < groups; ++g) {
      row[static_cast<std::size_t>(2 * g)] = ops_.harmonics[static_cast<std::size_t>(g)].sin_response[r];
      row[static_cast<std::size_t>(2 * g + 1)] = ops_.harmonics[static_cast<std::size_t>(g)].cos_response[r];
    }
    h.set_row(r, 0, row.data(), 2 * groups);
  }
  harmonics_ = h.build();
  harmonic_weights_.setZero(2 * groups);
  // The vectors now live in harmonics_ (with their repeats stored once); keep the frequencies.
  for (HarmonicResponse& r : ops_.harmonics) {
    r.sin_response = Vector();
    r.cos_response = Vector();
  }
  springs_.resize(static_cast<std::size_t>(m));
  for (Index j = 0; j < m; ++j) {
    SpringRow& r = springs_[static_cast<std::size_t>(j)];
    r = SpringRow{-1, -1, 0.0, 0.0, ops_.stiffnesses[j] * ops_.gaps[j]};
  }
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows(ops_.gap_rows);
  for (Index j = 0; j < m; ++j) {
    SpringRow& r = springs_[static_cast<std::size_t>(j)];
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, j); it; ++it) {
      if (r.dof_a < 0) {
        r.dof_a = it.col();
        r.k_a = it.value();
      } else {
        r.dof_b = it.col();
        r.k_b = it.value();
      }
    }
    if (r.dof_a < 0) r.dof_a = 0;  // no entries at all: a spring that never pushes (k_a = 0)
  }
  // Springs in the order in which the sweep finishes their displacements, and by degree of
  // freedom.
  by_final_dof_.resize(springs_.size());
  for (std::size_t j = 0; j < springs_.size(); ++j) by_final_dof_[j] = static_cast<int>(j);
  std::stable_sort(by_final_dof_.begin(), by_final_dof_.end(),
                   [&](int a, int b) { return final_dof(a) < final_dof(b); });
  // The same springs as a banded matrix, and the springs finished by each tile when they finish
  // in the order of their numbering (chains: always).
  Index gap_width = m > 0 ? 1 : 0;
  for (const SpringRow& r : springs_) {
    if (r.dof_b >= 0) gap_width = std::max(gap_width, 2 * std::abs(r.dof_a - r.dof_b) + 1);
  }
  BandedMatrixBuilder gb(m, 2 * n_, gap_width);
  std::vector<double> gap_row(static_cast<std::size_t>(std::max<Index>(gap_width, 1)));
  offsets_.resize(m);
  bool in_order = true;
  for (Index j = 0; j < m; ++j) {
    const SpringRow& r = springs_[static_cast<std::size_t>(j)];
    const Index lo = r.dof_b >= 0 ? std::min(r.dof_a, r.dof_b) : r.dof_a;
    const Index hi = r.dof_b >= 0 ? std::max(r.dof_a, r.dof_b) : r.dof_a;
    std::fill(gap_row.begin(), gap_row.end(), 0.0);
    gap_row[static_cast<std::size_t>(2 * (r.dof_a - lo))] = -r.k_a;
    if (r.dof_b >= 0) gap_row[static_cast<std::size_t>(2 * (r.dof_b - lo))] = -r.k_b;
    gb.set_row(j, 2 * lo, gap_row.data(), 2 * (hi - lo) + 1);
    offsets_[j] = r.offset;
    if (j > 0 && final_dof(static_cast<int>(j)) < final_dof(static_cast<int>(j - 1))) {
      in_order = false;
    }
  }
  gap_matrix_ = gb.build();
  if (in_order) {
    Index j = 0;
    for (Index r0 = 0; r0 < 2 * n_; r0 += kTileRows) {
      const Index r1 = std::min(2 * n_, r0 + kTileRows);
      while (j < m && 2 * final_dof(static_cast<int>(j)) < r1) ++j;
      tile_springs_end_.push_back(j);
    }
  }
  dof_springs_start_.assign(static_cast<std::size_t>(n_ + 1), 0);
  for (const SpringRow& r : springs_) {
    for (Index d : {r.dof_a, r.dof_b}) {
      if (d >= 0) ++dof_springs_start_[static_cast<std::size_t>(d + 1)];
    }
  }
  for (Index d = 0; d < n_; ++d) {
    dof_springs_start_[static_cast<std::size_t>(d + 1)] +=
        dof_springs_start_[static_cast<std::size_t>(d)];
  }
  dof_springs_.assign(static_cast<std::size_t>(dof_springs_start_.back()), 0);
  std::vector<Index> fill(dof_springs_start_.begin(), dof_springs_start_.end() - 1);
  for (std::size_t j = 0; j < springs_.size(); ++j) {
    for (Index d : {springs_[j].dof_a, springs_[j].dof_b}) {
      if (d >= 0) {
        dof_springs_[static_cast<std::size_t>(fill[static_cast<std::size_t>(d)]++)] =
            static_cast<int>(j);
      }
    }
  }
  state_.setZero(2 * n_);
  bar_.setZero(2 * n_);
  forces_.setZero(m);
  q_.setZero(m);
}

void BandedPropagator::set_state(double t, const Eigen::Ref<const Vector>& x,
                                 const Eigen::Ref<const Vector>& v) {
  check_initial_state(t, x, v, n_);
  origin_ = t;
  steps_ = 0;
  for (Index i = 0; i < n_; ++i) {
    state_[2 * i] = x[i];
    state_[2 * i + 1] = v[i];
  }
  // P = max(0, K2 W^T x - K2 Δ)
  for (std::size_t j = 0; j < springs_.size(); ++j) {
    const SpringRow& r = springs_[j];
    double g = r.k_a * x[r.dof_a] - r.offset;
    if (r.dof_b >= 0) g += r.k_b * x[r.dof_b];
    forces_[static_cast<Index>(j)] = std::max(0.0, g);
  }
  acting_.clear();
  for (Index j = 0; j < forces_.size(); ++j) {
    if (forces_[j] != 0.0) acting_.push_back(static_cast<int>(j));
  }
  if (!springs_.empty()) solver_.reset_active_set(forces_);
}


void BandedPropagator::step() {
  const double t = time();
  const Index rows = 2 * n_;
  const Index m = static_cast<Index>(springs_.size());
  double* bar = bar_.data();
  for (std::size_t g = 0; g < ops_.harmonics.size(); ++g) {
    const double w = ops_.harmonics[g].omega * t;
    harmonic_weights_[static_cast<Index>(2 * g)] = std::sin(w);
    harmonic_weights_[static_cast<Index>(2 * g + 1)] = std::cos(w);
  }
  // v̄ = T v + Ψ P_k + Σ (sin ωt h_sin + cos ωt h_cos), max |v̄| and the LCP's q, tile by tile so
  // that each tile of v̄ is still in cache when the load terms, the check and q read it. With few
  // forces acting, Ψ P_k is added afterwards from their columns, and the rows and springs it
  // touches are checked and formed again.
  const bool many_acting = 4 * static_cast<Index>(acting_.size()) > m;
  // One tile: v̄'s rows [r0, r1), returning their largest |v̄_i|.
  const auto tile_rows = [&](Index r0, Index r1) {
    double tile_largest = 0.0;
    ops_.transition.multiply(state_.data(), bar, r0, r1);
    if (many_acting) ops_.force_now.multiply_add(forces_.data(), bar, r0, r1);
    if (harmonics_.cols() > 0) {
      tile_largest = harmonics_.multiply_add_max_abs(harmonic_weights_.data(), bar, r0, r1);
    } else {
      for (Index r = r0; r < r1; ++r) tile_largest = larger(tile_largest, bar[r]);
    }
    // Infinity for a NaN, so that the largest over the tiles keeps it.
    return std::isnan(tile_largest) ? std::numeric_limits<double>::infinity() : tile_largest;
  };
  // The springs finished by one tile, [begin, end), formed from its rows.
  const auto tile_springs = [&](std::size_t tile) {
    const Index begin = tile == 0 ? 0 : tile_springs_end_[tile - 1];
    const Index end = tile_springs_end_[tile];
    gap_matrix_.multiply(bar, q_.data(), begin, end);
    for (Index j = begin; j < end; ++j) q_[j] += offsets_[j];
  };
  double largest = 0.0;
  const auto tiles = static_cast<std::size_t>((rows + kTileRows - 1) / kTileRows);
  const bool by_tiles = springs_.empty() || tile_springs_end_.size() == tiles;
  if (by_tiles && numerics_detail::spread_rows(rows)) {
    // Long chains (10^5 masses and more): the tiles spread over the threads, in two phases. A
    // spring's row reads v̄ on both sides of a tile boundary (a spring between the last mass of
    // one tile and the first of the next, and the padding of short rows), so every tile of v̄ is
    // finished (the barrier at the end of the first loop) before any spring is formed. Each
    // thread writes only its own rows of v̄ and its own springs of q: the result is the serial
    // one to the bit.
    const auto count = static_cast<long>(tiles);
#pragma omp parallel
    {
#pragma omp for schedule(static) reduction(max : largest)
      for (long tile = 0; tile < count; ++tile) {
        const Index r0 = static_cast<Index>(tile) * kTileRows;
        largest = std::max(largest, tile_rows(r0, std::min(rows, r0 + kTileRows)));
      }
      if (!springs_.empty()) {
#pragma omp for schedule(static)
        for (long tile = 0; tile < count; ++tile) tile_springs(static_cast<std::size_t>(tile));
      }
    }
  } else {
    std::size_t next = 0;  // into by_final_dof_
    std::size_t tile = 0;
    for (Index r0 = 0; r0 < rows; r0 += kTileRows, ++tile) {
      const Index r1 = std::min(rows, r0 + kTileRows);
      largest = std::max(largest, tile_rows(r0, r1));
      if (by_tiles) {
        if (!springs_.empty()) tile_springs(tile);
      } else {
        while (next < by_final_dof_.size() && 2 * final_dof(by_final_dof_[next]) < r1) {
          form_q(by_final_dof_[next++]);
        }
      }
    }
  }
  if (!many_acting && !acting_.empty()) {
    const BandedMatrix& columns = force_now_columns_;
    columns.transpose_multiply_add(forces_.data(), acting_.data(),
                                   static_cast<Index>(acting_.size()), bar);
    for (int j : acting_) {
      const Index f = columns.first_column(j);
      for (Index k = 0; k < columns.width(); ++k) largest = larger(largest, bar[f + k]);
      for (Index d = f / 2; d <= (f + columns.width() - 1) / 2 && d < n_; ++d) {
        for (Index e = dof_springs_start_[static_cast<std::size_t>(d)];
             e < dof_springs_start_[static_cast<std::size_t>(d + 1)]; ++e) {
          form_q(dof_springs_[static_cast<std::size_t>(e)]);
        }
      }
    }
  }
  // P_{k+1}, in place (P_k is no longer needed).
  if (!springs_.empty() && std::isfinite(largest)) {
    last_pivots_ = solver_.solve_forces(q_, forces_).pivots;
    acting_ = solver_.active_set();
  } else {
    last_pivots_ = 0;
  }
  // v = v̄ + Φ P_{k+1}; the rows it changes are checked again.
  largest = add_forces_checked(ops_.force_next, force_next_columns_, forces_, acting_, bar, largest);
  state_.swap(bar_);
  ++steps_;
  if (!(largest <= bound_)) {
    throw_divergence(time(), state_.allFinite() ? largest : kNotFinite, bound_);
  }
}

void BandedPropagator::position(Vector& x) const {
  x.resize(n_);
  for (Index i = 0; i < n_; ++i) x[i] = state_[2 * i];
}

void BandedPropagator::velocity(Vector& v) const {
  v.resize(n_);
  for (Index i = 0; i < n_; ++i) v[i] = state_[2 * i + 1];
}

Vector BandedPropagator::spring_forces() const {
  Vector p(forces_.size());
  for (Index j = 0; j < forces_.size(); ++j) {
    p[ops_.spring_order[static_cast<std::size_t>(j)]] = forces_[j];
  }
  return p;
}

std::size_t BandedPropagator::memory_bytes() const {
  std::size_t bytes = ops_.transition.memory_bytes() + ops_.force_now.memory_bytes() +
                      ops_.force_next.memory_bytes() + ops_.lcp_matrix.memory_bytes() +
                      force_now_columns_.memory_bytes() + force_next_columns_.memory_bytes() +
                      harmonics_.memory_bytes();
  bytes += static_cast<std::size_t>(state_.size() + bar_.size() + 2 * forces_.size()) *
           sizeof(double);
  bytes += springs_.size() * sizeof(SpringRow) + gap_matrix_.memory_bytes() +
           static_cast<std::size_t>(offsets_.size()) * sizeof(double);
  return bytes;
}

}  // namespace pwl
