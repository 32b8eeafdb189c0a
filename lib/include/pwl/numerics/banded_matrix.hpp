#pragma once
// A banded matrix stored by rows, with identical rows stored once.
//
// Row i keeps its entries in one run of width() consecutive columns starting at
// first_column(i); everything outside the run is zero. The runs may start anywhere (the matrix
// need not be square, and a row of the interleaved state [x_0, x_0', x_1, x_1', ...] can be
// matched with a column range of spring forces), which covers every operator of the banded
// precise integration with one type. Near the ends of a structure a run is shifted so that it
// stays inside the matrix and the entries it gains are zeros.
//
// In a periodic structure almost every row of the step's operators is the same row shifted
// (He, Gao & Zhong 2018, §2: "the exponential of a periodic structure has many identical and
// zero entries, which need not be computed or stored"). The builder keeps one copy of each
// distinct row (bitwise equal values), so a uniform chain of 10^5 masses stores a few dozen
// rows, and a product with it streams only the vectors: memory and time per product grow like
// the number of rows times the width, with a constant set by the arithmetic rather than by the
// memory bus. A chain whose cells all differ simply stores every row.
//
// The products do not read per-row bookkeeping either: the rows are described by segments in
// which the stored row and the first column repeat with a period (for the interleaved state:
// the x and x' rows of one mass, then the same two rows one mass further), so a product streams
// only its vectors.
#include <array>
#include <cstdint>
#include <vector>

#include "pwl/types.hpp"

namespace pwl {

struct AxisRepeat;

class BandedMatrix {
 public:
  BandedMatrix() = default;

  Index rows() const { return rows_; }
  Index cols() const { return cols_; }
  // Entries stored per row.
  Index width() const { return width_; }
  // Column of the first stored entry of row i.
  Index first_column(Index i) const { return first_[static_cast<std::size_t>(i)]; }
  // The width() stored values of row i (shared with identical rows).
  const double* row_values(Index i) const {
    return values_.data() +
           static_cast<std::size_t>(pool_index_[static_cast<std::size_t>(i)]) *
               static_cast<std::size_t>(width_);
  }
  // Entry (i, j); zero outside row i's run.
  double coeff(Index i, Index j) const;
  // Distinct value rows kept.
  Index stored_rows() const { return width_ > 0 ? static_cast<Index>(values_.size()) / width_ : 0; }
  // Bytes held (values and the per-row bookkeeping).
  std::size_t memory_bytes() const;
  // Largest i - j and j - i over the stored entries that are non-zero (the lower and upper
  // bandwidths of a square matrix).
  Index lower_bandwidth() const;
  Index upper_bandwidth() const;

  // y = A x and y += A x. x has cols() entries, y rows(). y must not alias x. Products over
  // 10^5 rows or more are spread over the OpenMP threads in row blocks (same result to the bit).
  void multiply(const double* x, double* y) const;
  void multiply_add(const double* x, double* y) const;
  // The same for rows [row_begin, row_end) only (a tile of a longer sweep).
  void multiply(const double* x, double* y, Index row_begin, Index row_end) const;
  void multiply_add(const double* x, double* y, Index row_begin, Index row_end) const;
  // out[c] = (A x)_{rows[c]} for the listed rows only, c < count: O(count · width) (the active
  // springs of an LCP, and the slacks that can turn negative). out has count entries.
  void multiply_listed_rows(const double* x, const int* rows, Index count, double* out) const;
  // y += A^T x, row by row, skipping the rows where x is zero: with A = B^T stored by rows, this
  // is y += B x in work proportional to the non-zeros of x (few springs in contact at a time).
  // x has rows() entries, y cols().
  void transpose_multiply_add(const double* x, double* y) const;
  // The same over the listed rows only (the non-zeros of x): O(count · width).
  void transpose_multiply_add(const double* x, const int* rows, Index count, double* y) const;
  // y += A x, returning the largest |y_i| after the update (infinity if some y_i is not
  // finite): a product and a divergence check in one sweep.
  double multiply_add_max_abs(const double* x, double* y) const;
  double multiply_add_max_abs(const double* x, double* y, Index row_begin, Index row_end) const;
  // Segments describing the rows (see above); for tests and diagnostics.
  Index segments() const { return static_cast<Index>(segments_.size()); }
  Vector operator*(const Vector& x) const;

  Matrix to_dense() const;
  // Keeps the entries of a dense matrix with |i - j| <= half_width (square or not: the band of
  // a rectangular matrix follows its diagonal scaled by cols/rows). For tests and small inputs.
  static BandedMatrix from_dense(const Matrix& A, Index half_width);
  // The band that holds every non-zero of A: each row's run starts at its first non-zero.
  static BandedMatrix from_dense_nonzeros(const Matrix& A);
  // The same for a sparse matrix, in O(non-zeros): the equation of motion's K, C and spring
  // directions of a chain as banded operators, whose products stream their vectors (the rows of
  // a uniform chain are stored once) instead of gathering through column indices.
  static BandedMatrix from_sparse_nonzeros(const SparseMatrix& A);

  static constexpr int kMaxPeriod = 8;
  // Rows [row_begin, row_end): row row_begin + k·period + φ stores pool row pool[φ] + k·pool_step
  // and starts at column first[φ] + k·column_step (pool_step = 0 where rows repeat, = period
  // where every row is stored, e.g. when the cells differ).
  struct Segment {
    Index row_begin = 0, row_end = 0;
    int period = 1;
    Index column_step = 0;
    std::int32_t pool_step = 0;
    std::array<std::int32_t, kMaxPeriod> pool{};
    std::array<Index, kMaxPeriod> first{};
  };
  const std::vector<Segment>& row_segments() const { return segments_; }
  const double* pool_row(std::int32_t p) const {
    return values_.data() + static_cast<std::size_t>(p) * static_cast<std::size_t>(width_);
  }

 private:
  friend class BandedMatrixBuilder;
  friend BandedMatrix repeat_period(const BandedMatrix& A, const AxisRepeat& rows,
                                    const AxisRepeat& cols);
  void find_segments();
  double max_abs_rows(const double* x, double* y, Index row_begin, Index row_end) const;
  Index rows_ = 0;
  Index cols_ = 0;
  Index width_ = 0;
  std::vector<Index> first_;          // per row
  std::vector<std::int32_t> pool_index_;  // per row: which stored row holds its values
  std::vector<double> values_;        // stored rows, width_ each
  std::vector<Segment> segments_;     // the rows again, for the products
};

// Fills a BandedMatrix row by row (any order, every row exactly once), keeping one copy of each
// distinct row.
class BandedMatrixBuilder {
 public:
  // width is clamped to cols. With share_rows = false every row gets its own storage (for
  // comparisons of the memory effect).
  BandedMatrixBuilder(Index rows, Index cols, Index width, bool share_rows = true);

  Index width() const { return matrix_.width_; }
  // Sets row i: `values` holds the entries of columns [first, first + span) (span <= width()).
  // The run is placed so that it stays inside the matrix: it starts at
  // clamp(first, 0, cols - width()), and the entries it gains are zero.
  void set_row(Index i, Index first, const double* values, Index span);
  BandedMatrix build();

 private:
  struct Bucket {
    std::uint64_t hash;
    std::int32_t pool;
  };
  std::int32_t intern(const double* row);
  // Notes pool row p as the most recently used one (recent_, newest first) and returns it.
  std::int32_t remember(std::int32_t p) {
    if (recent_[0] == p) return p;
    for (std::size_t k = recent_.size() - 1; k > 0; --k) recent_[k] = recent_[k - 1];
    recent_[0] = p;
    return p;
  }

  BandedMatrix matrix_;
  bool share_;
  std::vector<double> scratch_;
  std::vector<std::uint8_t> filled_;
  // Open-addressing table of stored rows by hash.
  std::vector<Bucket> table_;
  std::size_t table_used_ = 0;
  std::array<std::int32_t, BandedMatrix::kMaxPeriod> recent_{-1, -1, -1, -1, -1, -1, -1, -1};
};

// Products that build the step's operators (sizes must agree; InputError otherwise).
// A (banded) times S (sparse): row i of the result spans the columns S reaches from the
// non-zero entries of row i of A.
BandedMatrix multiply(const BandedMatrix& A, const SparseMatrix& S);
// S (sparse) times B (banded).
BandedMatrix multiply(const SparseMatrix& S, const BandedMatrix& B);
// diag * I + A for a square A (the band widens to hold the diagonal if needed).
BandedMatrix add_diagonal(const BandedMatrix& A, const Vector& diag);
// Rows first, first + stride, first + 2 stride, ... of A (e.g. the displacement rows of an
// interleaved state operator).
BandedMatrix select_rows(const BandedMatrix& A, Index first, Index stride);
// A^T, banded: row j holds column j of A between the first and last rows whose runs reach it.
BandedMatrix transpose(const BandedMatrix& A);

// A periodic stretch along one axis of an operator: `before` rows (or columns) come before a
// cut, `period` rows make one period of the structure, and `copies` periods are inserted at the
// cut (construction from the period, lib/src/banded/periodic_cut.hpp).
struct AxisRepeat {
  Index before = 0;
  Index period = 0;
  Index copies = 0;
  Index inserted() const { return period * copies; }
};
// A with `rows.copies` periods of rows inserted at the cut: row before + k·period + φ (k <
// copies) is row before - period + φ of A moved (k + 1)·cols.period columns on, and the rows
// after the cut are A's moved cols.inserted() columns on. The stored rows are A's, shared (no
// row is computed or compared), so this costs one pass over the rows.
BandedMatrix repeat_period(const BandedMatrix& A, const AxisRepeat& rows, const AxisRepeat& cols);

}  // namespace pwl
