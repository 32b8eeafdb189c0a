#include "pwl/numerics/banded_matrix.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <utility>

#include <fmt/format.h>
#include "numerics/thread_rows.hpp"
#include "pwl/errors.hpp"

namespace pwl {
namespace {

using numerics_detail::over_row_blocks;
using numerics_detail::spread_rows;

using RowMajorSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Four independent accumulators so that the compiler can keep two SIMD lanes busy without
// reassociating a single sum.
inline double dot(const double* a, const double* x, Index w) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  Index k = 0;
  for (; k + 4 <= w; k += 4) {
    s0 += a[k] * x[k];
    s1 += a[k + 1] * x[k + 1];
    s2 += a[k + 2] * x[k + 2];
    s3 += a[k + 3] * x[k + 3];
  }
  for (; k < w; ++k) s0 += a[k] * x[k];
  return (s0 + s2) + (s1 + s3);
}

// Row sweeps y_i (+)= a_i · x[first_i ..], with the width a compile-time constant up to
// kFixedWidths: the dot products then unroll into full SIMD registers with a tree reduction,
// about 1.7 times the speed of the run-time loop at the widths of the step's operators.
constexpr int kFixedWidths = 64;
using RowKernel = void (*)(const BandedMatrix&, const double*, double*, Index, Index);

// The row bodies below are small; inlining them into the segment loops is what makes the loops
// fast (GCC would otherwise keep one out-of-line copy for the several call sites).
#define PWL_ALWAYS_INLINE __attribute__((always_inline))

// Walks rows [r0, r1) segment by segment: body(row, stored values, first column). Periods 1
// and 2 (a row per mass, or the x and x' rows of a mass) get loops of their own.
// Walks the segments that meet rows [r0, r1): body(segment, first row, end row) on each one's
// share of the range.
template <class Body>
inline void for_each_segment(const BandedMatrix& A, Index r0, Index r1, Body&& body) {
  const auto& segments = A.row_segments();
  auto it = std::upper_bound(segments.begin(), segments.end(), r0,
                             [](Index r, const BandedMatrix::Segment& s) { return r < s.row_end; });
  for (; it != segments.end() && it->row_begin < r1; ++it) {
    body(*it, std::max(it->row_begin, r0), std::min(it->row_end, r1));
  }
}

template <class Body>
inline void for_each_row(const BandedMatrix& A, Index r0, Index r1, Body&& body) {
  const Index w = A.width();
  for_each_segment(A, r0, r1, [&](const BandedMatrix::Segment& s, Index begin, Index end) {
    const Index P = s.period, C = s.column_step;
    const Index values_step = static_cast<Index>(s.pool_step) * w;
    Index k = (begin - s.row_begin) / P, phase = (begin - s.row_begin) % P;
    const double* a0 = A.pool_row(s.pool[0]);
    const Index f0 = s.first[0];
    if (P == 1) {
      for (Index r = begin; r < end; ++r, ++k) body(r, a0 + k * values_step, f0 + k * C);
      return;
    }
    if (P == 2) {
      const double* a1 = A.pool_row(s.pool[1]);
      const Index f1 = s.first[1];
      Index r = begin;
      if (phase == 1 && r < end) {
        body(r, a1 + k * values_step, f1 + k * C);
        ++r;
        ++k;
      }
      for (; r + 1 < end; r += 2, ++k) {
        body(r, a0 + k * values_step, f0 + k * C);
        body(r + 1, a1 + k * values_step, f1 + k * C);
      }
      if (r < end) body(r, a0 + k * values_step, f0 + k * C);
      return;
    }
    for (Index r = begin; r < end; ++r) {
      body(r, A.pool_row(s.pool[static_cast<std::size_t>(phase)]) + k * values_step,
           s.first[static_cast<std::size_t>(phase)] + k * C);
      if (++phase == P) {
        phase = 0;
        ++k;
      }
    }
  });
}

template <bool Add>
void generic_rows(const BandedMatrix& A, const double* x, double* y, Index r0, Index r1) {
  const Index w = A.width();
  for_each_row(A, r0, r1, [&](Index r, const double* a, Index first) PWL_ALWAYS_INLINE {
    const double d = dot(a, x + first, w);
    if constexpr (Add) {
      y[r] += d;
    } else {
      y[r] = d;
    }
  });
}

// Up to this width, stretches where one stored row repeats one column further each row (a
// Toeplitz band: K, C and the spring directions of a uniform chain) are applied as a stencil:
// the W coefficients held in registers and the rows swept together, vectorised across rows
// instead of one short dot product per row.
constexpr int kStencilWidth = 8;

template <int W, bool Add>
void fixed_rows(const BandedMatrix& A, const double* x, double* y, Index r0, Index r1) {
  using Row = Eigen::Matrix<double, W, 1>;
  const auto by_rows = [&](Index b, Index e) {
    for_each_row(A, b, e, [&](Index r, const double* a, Index first) PWL_ALWAYS_INLINE {
      const double d = Eigen::Map<const Row>(a).dot(Eigen::Map<const Row>(x + first));
      if constexpr (Add) {
        y[r] += d;
      } else {
        y[r] = d;
      }
    });
  };
  if constexpr (W > kStencilWidth) {
    by_rows(r0, r1);
  } else {
    for_each_segment(A, r0, r1, [&](const BandedMatrix::Segment& s, Index begin, Index end) {
      if (s.period != 1 || s.pool_step != 0 || s.column_step != 1) {
        by_rows(begin, end);
        return;
      }
      std::array<double, W> a{};
      std::copy_n(A.pool_row(s.pool[0]), W, a.begin());
      // Row begin + i's run starts at column first[0] + (begin - row_begin) + i.
      const double* xs = x + s.first[0] + (begin - s.row_begin);
      for (Index r = begin; r < end; ++r) {
        const double* xr = xs + (r - begin);
        double d = a[0] * xr[0];
        for (int k = 1; k < W; ++k) d += a[static_cast<std::size_t>(k)] * xr[k];
        if constexpr (Add) {
          y[r] += d;
        } else {
          y[r] = d;
        }
      }
    });
  }
}

template <bool Add, int... Ws>
constexpr std::array<RowKernel, sizeof...(Ws) + 1> kernel_table(std::integer_sequence<int, Ws...>) {
  return {&generic_rows<Add>, &fixed_rows<Ws + 1, Add>...};
}

// A table's kernel for a width: the compile-time one up to kFixedWidths, the run-time loop
// (entry 0) past it.
template <class Table>
auto kernel_for_width(const Table& table, Index width) {
  return width >= 1 && width <= kFixedWidths ? table[static_cast<std::size_t>(width)] : table[0];
}

template <bool Add>
RowKernel row_kernel(Index width) {
  static constexpr auto table =
      kernel_table<Add>(std::make_integer_sequence<int, kFixedWidths>{});
  return kernel_for_width(table, width);
}

// Listed rows: out[c] = a_{rows[c]} · x[first ..], the width fixed at compile time as above.
using ListedKernel = void (*)(const BandedMatrix&, const double*, const int*, Index, double*);

void generic_listed_rows(const BandedMatrix& A, const double* x, const int* rows, Index count,
                         double* out) {
  for (Index c = 0; c < count; ++c) {
    out[c] = dot(A.row_values(rows[c]), x + A.first_column(rows[c]), A.width());
  }
}

template <int W>
void fixed_listed_rows(const BandedMatrix& A, const double* x, const int* rows, Index count,
                       double* out) {
  using Row = Eigen::Matrix<double, W, 1>;
  for (Index c = 0; c < count; ++c) {
    out[c] = Eigen::Map<const Row>(A.row_values(rows[c]))
                 .dot(Eigen::Map<const Row>(x + A.first_column(rows[c])));
  }
}

template <int... Ws>
constexpr std::array<ListedKernel, sizeof...(Ws) + 1> listed_table(
    std::integer_sequence<int, Ws...>) {
  return {&generic_listed_rows, &fixed_listed_rows<Ws + 1>...};
}

ListedKernel listed_kernel(Index width) {
  static constexpr auto table = listed_table(std::make_integer_sequence<int, kFixedWidths>{});
  return kernel_for_width(table, width);
}

void check_range(Index r0, Index r1, Index rows) {
  if (r0 < 0 || r1 > rows || r0 > r1) {
    throw InputError(fmt::format("banded product: rows [{}, {}) outside 0..{}", r0, r1, rows));
  }
}

std::uint64_t hash_row(const double* row, Index w) {
  std::uint64_t h = 0x9e3779b97f4a7c15ULL ^ static_cast<std::uint64_t>(w);
  for (Index k = 0; k < w; ++k) {
    std::uint64_t bits;
    std::memcpy(&bits, row + k, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 31;
  }
  return h;
}

}  // namespace

double BandedMatrix::coeff(Index i, Index j) const {
  const Index k = j - first_column(i);
  if (k < 0 || k >= width_) return 0.0;
  return row_values(i)[k];
}

std::size_t BandedMatrix::memory_bytes() const {
  return values_.size() * sizeof(double) + first_.size() * sizeof(Index) +
         pool_index_.size() * sizeof(std::int32_t);
}

Index BandedMatrix::lower_bandwidth() const {
  Index b = 0;
  for (Index i = 0; i < rows_; ++i) {
    const double* a = row_values(i);
    const Index f = first_column(i);
    for (Index k = 0; k < width_; ++k) {
      if (a[k] != 0.0) {
        b = std::max(b, i - (f + k));
        break;  // the first non-zero is the farthest to the left
      }
    }
  }
  return b;
}

Index BandedMatrix::upper_bandwidth() const {
  Index b = 0;
  for (Index i = 0; i < rows_; ++i) {
    const double* a = row_values(i);
    const Index f = first_column(i);
    for (Index k = width_ - 1; k >= 0; --k) {
      if (a[k] != 0.0) {
        b = std::max(b, f + k - i);
        break;
      }
    }
  }
  return b;
}

void BandedMatrix::multiply(const double* x, double* y) const { multiply(x, y, 0, rows_); }

void BandedMatrix::multiply_add(const double* x, double* y) const {
  multiply_add(x, y, 0, rows_);
}

void BandedMatrix::multiply(const double* x, double* y, Index row_begin, Index row_end) const {
  check_range(row_begin, row_end, rows_);
  if (width_ == 0) {
    std::fill(y + row_begin, y + row_end, 0.0);
    return;
  }
  const RowKernel kernel = row_kernel<false>(width_);
  over_row_blocks(row_begin, row_end, [&](Index b, Index e) { kernel(*this, x, y, b, e); });
}

void BandedMatrix::multiply_add(const double* x, double* y, Index row_begin,
                                Index row_end) const {
  check_range(row_begin, row_end, rows_);
  if (width_ == 0) return;
  const RowKernel kernel = row_kernel<true>(width_);
  over_row_blocks(row_begin, row_end, [&](Index b, Index e) { kernel(*this, x, y, b, e); });
}

void BandedMatrix::multiply_listed_rows(const double* x, const int* rows, Index count,
                                        double* out) const {
  if (width_ == 0) {
    std::fill(out, out + count, 0.0);
    return;
  }
  listed_kernel(width_)(*this, x, rows, count, out);
}

void BandedMatrix::transpose_multiply_add(const double* x, double* y) const {
  for (Index i = 0; i < rows_; ++i) {
    const double xi = x[i];
    if (xi == 0.0) continue;
    const double* a = row_values(i);
    double* out = y + first_column(i);
    for (Index k = 0; k < width_; ++k) out[k] += xi * a[k];
  }
}

void BandedMatrix::transpose_multiply_add(const double* x, const int* rows, Index count,
                                          double* y) const {
  for (Index c = 0; c < count; ++c) {
    const Index i = rows[c];
    const double xi = x[i];
    if (xi == 0.0) continue;
    const double* a = row_values(i);
    double* out = y + first_column(i);
    for (Index k = 0; k < width_; ++k) out[k] += xi * a[k];
  }
}

double BandedMatrix::multiply_add_max_abs(const double* x, double* y) const {
  return multiply_add_max_abs(x, y, 0, rows_);
}

double BandedMatrix::multiply_add_max_abs(const double* x, double* y, Index row_begin,
                                          Index row_end) const {
  check_range(row_begin, row_end, rows_);
  if (!spread_rows(row_end - row_begin)) return max_abs_rows(x, y, row_begin, row_end);
  double largest = 0.0;
  std::mutex lock;
  over_row_blocks(row_begin, row_end, [&](Index b, Index e) {
    const double mine = max_abs_rows(x, y, b, e);
    const std::lock_guard<std::mutex> guard(lock);
    largest = std::max(largest, mine);
  });
  return largest;
}

double BandedMatrix::max_abs_rows(const double* x, double* y, Index row_begin,
                                  Index row_end) const {
  double largest = 0.0;
  bool finite = true;
  const auto update = [&](Index r, double d) PWL_ALWAYS_INLINE {
    const double v = y[r] + d;
    y[r] = v;
    const double m = std::abs(v);
    finite &= m <= std::numeric_limits<double>::max();
    largest = std::max(largest, m);
  };
  auto it = std::upper_bound(segments_.begin(), segments_.end(), row_begin,
                             [](Index r, const Segment& s) { return r < s.row_end; });
  for (; it != segments_.end() && it->row_begin < row_end; ++it) {
    const Segment& s = *it;
    const Index begin = std::max(s.row_begin, row_begin), end = std::min(s.row_end, row_end);
    const Index P = s.period;
    Index k = (begin - s.row_begin) / P, phase = (begin - s.row_begin) % P;
    if (s.column_step == 0 && s.pool_step == 0) {
      // The same rows against the same entries of x (e.g. load responses of a periodic chain
      // times sin ωt, cos ωt): P dot products for the whole segment.
      std::array<double, kMaxPeriod> d{};
      for (Index p = 0; p < P; ++p) {
        d[static_cast<std::size_t>(p)] = dot(pool_row(s.pool[static_cast<std::size_t>(p)]),
                                             x + s.first[static_cast<std::size_t>(p)], width_);
      }
      for (Index r = begin; r < end; ++r) {
        update(r, d[static_cast<std::size_t>(phase)]);
        if (++phase == P) phase = 0;
      }
      continue;
    }
    const Index values_step = static_cast<Index>(s.pool_step) * width_;
    for (Index r = begin; r < end; ++r) {
      const double* a = pool_row(s.pool[static_cast<std::size_t>(phase)]) + k * values_step;
      update(r, dot(a, x + s.first[static_cast<std::size_t>(phase)] + k * s.column_step, width_));
      if (++phase == P) {
        phase = 0;
        ++k;
      }
    }
  }
  return finite ? largest : std::numeric_limits<double>::infinity();
}

void BandedMatrix::find_segments() {
  segments_.clear();
  const Index n = rows_;
  for (Index r = 0; r < n;) {
    // The period that covers the most rows from r on (the smallest on ties).
    Index best_len = 1;
    int best_period = 1;
    const auto first = [&](Index i) { return first_[static_cast<std::size_t>(i)]; };
    const auto pool = [&](Index i) { return pool_index_[static_cast<std::size_t>(i)]; };
    for (int P = 1; P <= kMaxPeriod && r + P < n; ++P) {
      const Index step = first(r + P) - first(r);
      const std::int32_t pool_step = pool(r + P) - pool(r);
      Index j = r + P;
      while (j < n && pool(j) == pool(j - P) + pool_step && first(j) == first(j - P) + step) ++j;
      if (j - r > best_len && j - r >= 2 * P) {
        best_len = j - r;
        best_period = P;
      }
    }
    Segment s;
    s.row_begin = r;
    s.row_end = r + best_len;
    s.period = best_period;
    if (best_len > best_period) {
      s.column_step = first(r + best_period) - first(r);
      s.pool_step = pool(r + best_period) - pool(r);
    }
    for (int phase = 0; phase < best_period && r + phase < n; ++phase) {
      s.pool[static_cast<std::size_t>(phase)] = pool_index_[static_cast<std::size_t>(r + phase)];
      s.first[static_cast<std::size_t>(phase)] = first_[static_cast<std::size_t>(r + phase)];
    }
    segments_.push_back(s);
    r += best_len;
  }
}

Vector BandedMatrix::operator*(const Vector& x) const {
  if (x.size() != cols_) {
    throw InputError(fmt::format("banded product: x has {} entries, the matrix {} columns",
                                 x.size(), cols_));
  }
  Vector y(rows_);
  multiply(x.data(), y.data());
  return y;
}

Matrix BandedMatrix::to_dense() const {
  Matrix A = Matrix::Zero(rows_, cols_);
  for (Index i = 0; i < rows_; ++i) {
    const double* a = row_values(i);
    for (Index k = 0; k < width_; ++k) A(i, first_column(i) + k) = a[k];
  }
  return A;
}

BandedMatrix BandedMatrix::from_dense(const Matrix& A, Index half_width) {
  if (half_width < 0) throw InputError(fmt::format("half_width = {} must be >= 0", half_width));
  BandedMatrixBuilder b(A.rows(), A.cols(), std::min<Index>(A.cols(), 2 * half_width + 1));
  std::vector<double> row(static_cast<std::size_t>(b.width()));
  for (Index i = 0; i < A.rows(); ++i) {
    const Index lo = std::clamp<Index>(i - half_width, 0, A.cols());
    const Index hi = std::clamp<Index>(i + half_width + 1, 0, A.cols());
    for (Index j = lo; j < hi; ++j) row[static_cast<std::size_t>(j - lo)] = A(i, j);
    b.set_row(i, lo, row.data(), hi - lo);
  }
  return b.build();
}

BandedMatrix BandedMatrix::from_dense_nonzeros(const Matrix& A) {
  Index width = A.cols() > 0 ? 1 : 0;
  std::vector<Index> lo(static_cast<std::size_t>(A.rows()), 0), hi(lo);
  for (Index i = 0; i < A.rows(); ++i) {
    Index first = -1, last = -1;
    for (Index j = 0; j < A.cols(); ++j) {
      if (A(i, j) != 0.0) {
        if (first < 0) first = j;
        last = j;
      }
    }
    if (first >= 0) {
      lo[static_cast<std::size_t>(i)] = first;
      hi[static_cast<std::size_t>(i)] = last + 1;
      width = std::max(width, last + 1 - first);
    }
  }
  BandedMatrixBuilder b(A.rows(), A.cols(), width);
  std::vector<double> row(static_cast<std::size_t>(width));
  for (Index i = 0; i < A.rows(); ++i) {
    const Index f = lo[static_cast<std::size_t>(i)], l = hi[static_cast<std::size_t>(i)];
    for (Index j = f; j < l; ++j) row[static_cast<std::size_t>(j - f)] = A(i, j);
    b.set_row(i, f, row.data(), l - f);
  }
  return b.build();
}

BandedMatrix BandedMatrix::from_sparse_nonzeros(const SparseMatrix& A) {
  const RowMajorSparse R(A);
  Index width = A.cols() > 0 ? 1 : 0;
  std::vector<Index> lo(static_cast<std::size_t>(A.rows()), 0), hi(lo);
  for (Index i = 0; i < A.rows(); ++i) {
    Index first = -1, last = -1;
    for (RowMajorSparse::InnerIterator it(R, i); it; ++it) {
      if (it.value() == 0.0) continue;
      if (first < 0 || it.col() < first) first = it.col();
      last = std::max(last, it.col());
    }
    if (first >= 0) {
      lo[static_cast<std::size_t>(i)] = first;
      hi[static_cast<std::size_t>(i)] = last + 1;
      width = std::max(width, last + 1 - first);
    }
  }
  BandedMatrixBuilder b(A.rows(), A.cols(), width);
  std::vector<double> row(static_cast<std::size_t>(std::max<Index>(width, 1)));
  for (Index i = 0; i < A.rows(); ++i) {
    const Index f = lo[static_cast<std::size_t>(i)], l = hi[static_cast<std::size_t>(i)];
    std::fill(row.begin(), row.end(), 0.0);
    for (RowMajorSparse::InnerIterator it(R, i); it; ++it) {
      if (it.value() != 0.0) row[static_cast<std::size_t>(it.col() - f)] = it.value();
    }
    b.set_row(i, f, row.data(), l - f);
  }
  return b.build();
}

// ---------------------------------------------------------------------------------------------

BandedMatrixBuilder::BandedMatrixBuilder(Index rows, Index cols, Index width, bool share_rows)
    : share_(share_rows) {
  if (rows < 0 || cols < 0 || width < 0) {
    throw InputError(fmt::format("banded matrix {}x{} of width {}: sizes must be >= 0", rows,
                                 cols, width));
  }
  if (rows > std::numeric_limits<std::int32_t>::max()) {
    throw InputError(fmt::format("banded matrix with {} rows: at most 2^31 - 1", rows));
  }
  matrix_.rows_ = rows;
  matrix_.cols_ = cols;
  matrix_.width_ = std::min(width, cols);
  matrix_.first_.assign(static_cast<std::size_t>(rows), 0);
  matrix_.pool_index_.assign(static_cast<std::size_t>(rows), 0);
  scratch_.assign(static_cast<std::size_t>(matrix_.width_), 0.0);
  filled_.assign(static_cast<std::size_t>(rows), 0);
  table_.assign(64, Bucket{0, -1});
}

void BandedMatrixBuilder::set_row(Index i, Index first, const double* values, Index span) {
  const Index w = matrix_.width_;
  const Index cols = matrix_.cols_;
  if (i < 0 || i >= matrix_.rows_) {
    throw InputError(fmt::format("banded matrix: row {} is outside 0..{}", i, matrix_.rows_ - 1));
  }
  if (span < 0 || span > w || first < 0 || first + span > cols) {
    throw InputError(fmt::format(
        "banded matrix: row {} run [{}, {}) does not fit a {}-column matrix of width {}", i,
        first, first + span, cols, w));
  }
  const Index start = std::clamp<Index>(first, 0, cols - w);
  std::fill(scratch_.begin(), scratch_.end(), 0.0);
  for (Index k = 0; k < span; ++k) scratch_[static_cast<std::size_t>(first + k - start)] = values[k];
  matrix_.first_[static_cast<std::size_t>(i)] = start;
  matrix_.pool_index_[static_cast<std::size_t>(i)] = intern(scratch_.data());
  filled_[static_cast<std::size_t>(i)] = 1;
}

std::int32_t BandedMatrixBuilder::intern(const double* row) {
  const Index w = matrix_.width_;
  std::vector<double>& pool = matrix_.values_;
  const auto append = [&]() {
    const auto index = static_cast<std::int32_t>(w > 0 ? pool.size() / static_cast<std::size_t>(w)
                                                       : 0);
    pool.insert(pool.end(), row, row + w);
    return index;
  };
  if (!share_) return append();
  if (w == 0) {
    return 0;
  }
  // A periodic structure's rows repeat within a few rows (the x and x' rows of a mass, then the
  // same two one mass further): compared with the last rows stored or found first, they are
  // found without hashing.
  for (const std::int32_t p : recent_) {
    if (p < 0) continue;
    const double* stored = pool.data() + static_cast<std::size_t>(p) * static_cast<std::size_t>(w);
    if (std::memcmp(stored, row, static_cast<std::size_t>(w) * sizeof(double)) == 0) {
      return remember(p);
    }
  }
  const std::uint64_t h = hash_row(row, w);
  std::size_t mask = table_.size() - 1;
  std::size_t slot = static_cast<std::size_t>(h) & mask;
  while (table_[slot].pool >= 0) {
    if (table_[slot].hash == h) {
      const double* stored =
          pool.data() + static_cast<std::size_t>(table_[slot].pool) * static_cast<std::size_t>(w);
      if (std::memcmp(stored, row, static_cast<std::size_t>(w) * sizeof(double)) == 0) {
        return remember(table_[slot].pool);
      }
    }
    slot = (slot + 1) & mask;
  }
  const std::int32_t index = remember(append());
  table_[slot] = Bucket{h, index};
  if (2 * ++table_used_ > table_.size()) {
    // Grow and re-insert.
    std::vector<Bucket> old;
    old.swap(table_);
    table_.assign(old.size() * 2, Bucket{0, -1});
    mask = table_.size() - 1;
    for (const Bucket& b : old) {
      if (b.pool < 0) continue;
      std::size_t s = static_cast<std::size_t>(b.hash) & mask;
      while (table_[s].pool >= 0) s = (s + 1) & mask;
      table_[s] = b;
    }
  }
  return index;
}

BandedMatrix BandedMatrixBuilder::build() {
  for (std::size_t i = 0; i < filled_.size(); ++i) {
    if (!filled_[i]) throw Error(fmt::format("banded matrix: row {} was never set", i));
  }
  if (matrix_.width_ == 0) {
    std::fill(matrix_.pool_index_.begin(), matrix_.pool_index_.end(), 0);
  }
  matrix_.find_segments();
  table_.clear();
  table_.shrink_to_fit();
  matrix_.values_.shrink_to_fit();
  return std::move(matrix_);
}

// ---------------------------------------------------------------------------------------------

BandedMatrix multiply(const BandedMatrix& A, const SparseMatrix& S) {
  if (A.cols() != S.rows()) {
    throw InputError(fmt::format("banded x sparse: {}x{} times {}x{}", A.rows(), A.cols(),
                                 S.rows(), S.cols()));
  }
  const RowMajorSparse R(S);
  const Index rows = A.rows(), w = A.width();
  std::vector<Index> lo(static_cast<std::size_t>(rows)), hi(static_cast<std::size_t>(rows));
  Index width = 0;
  for (Index i = 0; i < rows; ++i) {
    Index l = S.cols(), h = -1;
    const double* a = A.row_values(i);
    for (Index k = 0; k < w; ++k) {
      if (a[k] == 0.0) continue;
      for (RowMajorSparse::InnerIterator it(R, A.first_column(i) + k); it; ++it) {
        l = std::min(l, it.col());
        h = std::max(h, it.col());
      }
    }
    if (h < l) {
      l = 0;
      h = -1;
    }
    lo[static_cast<std::size_t>(i)] = l;
    hi[static_cast<std::size_t>(i)] = h + 1;
    width = std::max(width, h + 1 - l);
  }
  BandedMatrixBuilder b(rows, S.cols(), std::max<Index>(width, S.cols() > 0 ? 1 : 0));
  std::vector<double> row(static_cast<std::size_t>(std::max<Index>(width, 1)));
  for (Index i = 0; i < rows; ++i) {
    const Index l = lo[static_cast<std::size_t>(i)], span = hi[static_cast<std::size_t>(i)] - l;
    std::fill(row.begin(), row.end(), 0.0);
    const double* a = A.row_values(i);
    for (Index k = 0; k < w; ++k) {
      if (a[k] == 0.0) continue;
      for (RowMajorSparse::InnerIterator it(R, A.first_column(i) + k); it; ++it) {
        row[static_cast<std::size_t>(it.col() - l)] += a[k] * it.value();
      }
    }
    b.set_row(i, span > 0 ? l : 0, row.data(), std::max<Index>(span, 0));
  }
  return b.build();
}

BandedMatrix multiply(const SparseMatrix& S, const BandedMatrix& B) {
  if (S.cols() != B.rows()) {
    throw InputError(fmt::format("sparse x banded: {}x{} times {}x{}", S.rows(), S.cols(),
                                 B.rows(), B.cols()));
  }
  const RowMajorSparse R(S);
  const Index rows = S.rows(), w = B.width();
  std::vector<Index> lo(static_cast<std::size_t>(rows)), hi(static_cast<std::size_t>(rows));
  Index width = 0;
  for (Index j = 0; j < rows; ++j) {
    Index l = B.cols(), h = -1;
    for (RowMajorSparse::InnerIterator it(R, j); it; ++it) {
      l = std::min(l, B.first_column(it.col()));
      h = std::max(h, B.first_column(it.col()) + w - 1);
    }
    if (h < l) {
      l = 0;
      h = -1;
    }
    lo[static_cast<std::size_t>(j)] = l;
    hi[static_cast<std::size_t>(j)] = h + 1;
    width = std::max(width, h + 1 - l);
  }
  BandedMatrixBuilder b(rows, B.cols(), std::max<Index>(width, B.cols() > 0 ? 1 : 0));
  std::vector<double> row(static_cast<std::size_t>(std::max<Index>(width, 1)));
  for (Index j = 0; j < rows; ++j) {
    const Index l = lo[static_cast<std::size_t>(j)], span = hi[static_cast<std::size_t>(j)] - l;
    std::fill(row.begin(), row.end(), 0.0);
    for (RowMajorSparse::InnerIterator it(R, j); it; ++it) {
      const double* v = B.row_values(it.col());
      const Index offset = B.first_column(it.col()) - l;
      for (Index k = 0; k < w; ++k) row[static_cast<std::size_t>(offset + k)] += it.value() * v[k];
    }
    b.set_row(j, span > 0 ? l : 0, row.data(), std::max<Index>(span, 0));
  }
  return b.build();
}

BandedMatrix add_diagonal(const BandedMatrix& A, const Vector& diag) {
  if (A.rows() != A.cols() || diag.size() != A.rows()) {
    throw InputError(fmt::format("add_diagonal: a {}x{} matrix and {} diagonal entries", A.rows(),
                                 A.cols(), diag.size()));
  }
  const Index n = A.rows(), w = A.width();
  Index width = std::min<Index>(n, 1);
  for (Index i = 0; i < n; ++i) {
    const Index l = std::min(A.first_column(i), i);
    const Index h = std::max(A.first_column(i) + w - 1, i);
    width = std::max(width, h + 1 - l);
  }
  BandedMatrixBuilder b(n, n, width);
  std::vector<double> row(static_cast<std::size_t>(std::max<Index>(width, 1)));
  for (Index i = 0; i < n; ++i) {
    const Index l = std::min(A.first_column(i), i);
    const Index h = std::max(A.first_column(i) + w - 1, i);
    std::fill(row.begin(), row.end(), 0.0);
    const double* a = A.row_values(i);
    for (Index k = 0; k < w; ++k) row[static_cast<std::size_t>(A.first_column(i) + k - l)] = a[k];
    row[static_cast<std::size_t>(i - l)] += diag[i];
    b.set_row(i, l, row.data(), h + 1 - l);
  }
  return b.build();
}

BandedMatrix select_rows(const BandedMatrix& A, Index first, Index stride) {
  if (first < 0 || stride < 1) {
    throw InputError(fmt::format("select_rows: first = {} must be >= 0 and stride = {} >= 1",
                                 first, stride));
  }
  const Index rows = first < A.rows() ? (A.rows() - first + stride - 1) / stride : 0;
  BandedMatrixBuilder b(rows, A.cols(), A.width());
  for (Index r = 0; r < rows; ++r) {
    const Index i = first + r * stride;
    b.set_row(r, A.first_column(i), A.row_values(i), A.width());
  }
  return b.build();
}

}  // namespace pwl

namespace pwl {

BandedMatrix transpose(const BandedMatrix& A) {
  const Index rows = A.rows(), cols = A.cols(), w = A.width();
  std::vector<Index> lo(static_cast<std::size_t>(cols), rows), hi(static_cast<std::size_t>(cols), -1);
  for (Index i = 0; i < rows; ++i) {
    const double* a = A.row_values(i);
    for (Index k = 0; k < w; ++k) {
      if (a[k] == 0.0) continue;
      const auto j = static_cast<std::size_t>(A.first_column(i) + k);
      lo[j] = std::min(lo[j], i);
      hi[j] = std::max(hi[j], i);
    }
  }
  Index width = rows > 0 ? 1 : 0;
  for (Index j = 0; j < cols; ++j) {
    if (hi[static_cast<std::size_t>(j)] >= lo[static_cast<std::size_t>(j)]) {
      width = std::max(width, hi[static_cast<std::size_t>(j)] - lo[static_cast<std::size_t>(j)] + 1);
    }
  }
  BandedMatrixBuilder b(cols, rows, width);
  std::vector<double> row(static_cast<std::size_t>(std::max<Index>(width, 1)));
  for (Index j = 0; j < cols; ++j) {
    const Index l = lo[static_cast<std::size_t>(j)], h = hi[static_cast<std::size_t>(j)];
    if (h < l) {
      b.set_row(j, 0, row.data(), 0);
      continue;
    }
    for (Index i = l; i <= h; ++i) {
      const Index k = j - A.first_column(i);
      row[static_cast<std::size_t>(i - l)] = k >= 0 && k < w ? A.row_values(i)[k] : 0.0;
    }
    b.set_row(j, l, row.data(), h - l + 1);
  }
  return b.build();
}

BandedMatrix repeat_period(const BandedMatrix& A, const AxisRepeat& rows, const AxisRepeat& cols) {
  if (rows.before < rows.period || rows.before > A.rows() || rows.period < 0 ||
      rows.copies < 0 || cols.before > A.cols() || cols.period < 0 ||
      cols.copies != rows.copies) {
    throw Error(fmt::format(
        "banded matrix: cannot repeat rows [{}, {}) of a {}x{} matrix {} times ({} columns a "
        "period, {} copies)",
        rows.before - rows.period, rows.before, A.rows(), A.cols(), rows.copies, cols.period,
        cols.copies));
  }
  BandedMatrix out;
  out.rows_ = A.rows_ + rows.inserted();
  out.cols_ = A.cols_ + cols.inserted();
  out.width_ = A.width_;
  out.values_ = A.values_;
  const auto size = static_cast<std::size_t>(out.rows_);
  out.first_.resize(size);
  out.pool_index_.resize(size);
  const auto before = static_cast<std::size_t>(rows.before);
  std::copy_n(A.first_.begin(), before, out.first_.begin());
  std::copy_n(A.pool_index_.begin(), before, out.pool_index_.begin());
  for (Index k = 0; k < rows.copies; ++k) {
    const Index shift = (k + 1) * cols.period;
    for (Index phase = 0; phase < rows.period; ++phase) {
      const auto from = static_cast<std::size_t>(rows.before - rows.period + phase);
      const auto to = static_cast<std::size_t>(rows.before + k * rows.period + phase);
      out.first_[to] = A.first_[from] + shift;
      out.pool_index_[to] = A.pool_index_[from];
    }
  }
  const Index after = A.rows_ - rows.before;
  for (Index r = 0; r < after; ++r) {
    const auto from = static_cast<std::size_t>(rows.before + r);
    const auto to = static_cast<std::size_t>(rows.before + rows.inserted() + r);
    out.first_[to] = A.first_[from] + cols.inserted();
    out.pool_index_[to] = A.pool_index_[from];
  }
  out.find_segments();
  return out;
}

}  // namespace pwl
