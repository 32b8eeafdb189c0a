#pragma once
// Restarted GMRES for A x = b with A known only by its products (Y. Saad and M. H. Schultz, SIAM J.
// Sci. Stat. Comput. 7 (1986) 856-869): the Krylov solver of matrix-free Newton on the
// stroboscopic map of a long chain, and of the bordered systems of matrix-free continuation.
// Private to the orbits room.
//
// Krylov subspace recycling (GCRO-DR: M. L. Parks, E. de Sturler, G. Mackey, D. D. Johnson and
// S. Maiti, SIAM J. Sci. Comput. 28 (2006) 1651-1674). A sequence of systems A_i x = b_i whose
// operators change little or not at all (the right-hand sides of one bordered operator at a point
// of a curve; one Newton step after another) shares the directions GMRES is slowest to find: the
// eigenvectors of the smallest eigenvalues. GCRO-DR keeps k of them, as U with C = A U orthonormal,
// from the harmonic Ritz vectors of each cycle, and solves the next system in x0 + span U +
// K(P A, P r0) with P = I − C Cᵀ: the Arnoldi process runs on the projected operator, whose
// smallest eigenvalues are deflated, and the least-squares problem is the cycle's Hessenberg one
// (the part along C is solved exactly). For the same operator the space is used as it is, at no
// cost; for a new one either C = A U is formed again (k products, U taken to C's QR factor: the
// method of the paper) or the space is dropped and the next solve builds its own from its cycles.
// With no space kept (k = 0) this is GMRES, operation for operation.
//
// Which pays depends on how long a solve is. On the bordered systems of pwl's continuation,
// preconditioned by the open structure, a solve takes 6 to 16 products, and forming A U again
// costs more than deflation saves (a 300-mass period-doubling curve: 704 GMRES products with no
// recycling, 919 re-forming 2 vectors a new operator, 1083 re-forming 4; the branch before it 822,
// 919, 1083). Dropped at each new operator and kept across the right-hand sides of one (a curve's
// inner solves: k(m + 2) of them a Newton step) it costs nothing and saves: 704 -> 494 products
// with 10 vectors, and on the 1000-mass chain's Neimark-Sacker curves 11762 -> 8731
// (analysis/README.md, "Recycled Krylov subspaces"). Re-formed across Newton iterates, the space
// also changes the step: without the preconditioner a 300-mass orbit's Newton-Krylov met every
// forcing term in fewer products yet did not converge in 40 iterations, where dropping took 24.
// And on the 1000-mass chain's branch, 25 points: 909 products dropping, 1808 re-forming 10
// vectors, 1006 re-forming 2. So dropping is the default; ShootingOptions::gmres_reform (the
// CLI's --gmres-reform) re-forms.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::orbits::detail {

struct GmresResult {
  double relative_residual = 0.0;  // |b − A x| / |b|
  int products = 0;                // products with A (those that formed A U included)
};

// The subspace GCRO-DR carries from one solve to the next. `size` is k, the vectors kept (0:
// plain GMRES); U holds them (n × at most k) and C = A U, orthonormal, for the operator of the
// last solve. Call operator_changed() before a solve with another operator: with `reform` that
// solve forms A U again (k products) before its first cycle; without, the space is dropped.
struct RecycledSubspace {
  explicit RecycledSubspace(int kept = 0, bool reform_images = false)
      : size(kept), reform(reform_images) {}
  void operator_changed() {
    if (reform) {
      current = false;
    } else {
      clear();
    }
  }
  void clear() {
    U.resize(0, 0);
    C.resize(0, 0);
    current = false;
  }
  int size = 0;
  bool reform = false;
  Matrix U, C;
  bool current = false;
};

namespace gmres_detail {

// C = A U orthonormal for the current operator, U taken to match (U ← U R⁻¹ for A U = C R, the
// columns A U makes dependent dropped). Returns the products spent.
inline int form_recycled_image(const std::function<Vector(const Vector&)>& apply,
                               RecycledSubspace& s) {
  const Index n = s.U.rows(), k = s.U.cols();
  Matrix AU(n, k);
  for (Index i = 0; i < k; ++i) AU.col(i) = apply(s.U.col(i));
  const Eigen::ColPivHouseholderQR<Matrix> qr(AU);
  const Matrix R = qr.matrixR().topLeftCorner(k, k).triangularView<Eigen::Upper>();
  Index rank = 0;
  const double largest = std::abs(R(0, 0));
  // Columns beyond a condition of 1e8 dropped: A U − C grows like rounding times it.
  while (rank < k && std::abs(R(rank, rank)) > 1e-8 * largest) ++rank;
  if (!(largest > 0) || !AU.allFinite() || rank == 0) {
    s.clear();
    return static_cast<int>(k);
  }
  const Matrix Upermuted = s.U * qr.colsPermutation();
  s.C = qr.householderQ() * Matrix::Identity(n, rank);
  s.U = R.topLeftCorner(rank, rank)
            .triangularView<Eigen::Upper>()
            .solve<Eigen::OnTheRight>(Upermuted.leftCols(rank));
  s.current = true;
  return static_cast<int>(k);
}

// The next recycled space from one cycle: Ŵ = [U D, V_j] (D scales U's columns to one),
// V̂ = [C, V_{j+1}] and Ḡ = [D, B; 0, H̄] with A Ŵ = V̂ Ḡ. The harmonic Ritz pairs solve
// Ḡᵀ Ḡ z = θ Ḡᵀ V̂ᵀ Ŵ z; the k of smallest |θ| (a complex pair by its real and imaginary parts)
// span P, and with Ḡ P = Q R: C = V̂ Q, U = Ŵ P R⁻¹. Left unchanged where this is degenerate.
inline void update_recycled(RecycledSubspace& s, const Matrix& V, const Matrix& H, const Matrix& B,
                            Index used) {
  const Index n = V.rows(), k = s.U.cols(), dim = k + used;
  Vector d(k);
  for (Index i = 0; i < k; ++i) d(i) = 1.0 / s.U.col(i).norm();
  Matrix W(n, dim), Vhat(n, dim + 1), G = Matrix::Zero(dim + 1, dim);
  W.leftCols(k) = s.U * d.asDiagonal();
  W.rightCols(used) = V.leftCols(used);
  Vhat.leftCols(k) = s.C;
  Vhat.rightCols(used + 1) = V.leftCols(used + 1);
  G.topLeftCorner(k, k) = d.asDiagonal();
  G.block(0, k, k, used) = B.leftCols(used);
  G.block(k, k, used + 1, used) = H.topLeftCorner(used + 1, used);
  if (!W.allFinite() || !G.allFinite()) return;
  // Ḡᵀ Ḡ is positive definite (Ḡ has full column rank while Arnoldi has not broken down): the
  // eigenvalues λ = 1/θ of (ḠᵀḠ)⁻¹ Ḡᵀ V̂ᵀ Ŵ, the largest |λ| first.
  const Eigen::LLT<Matrix> left(G.transpose() * G);
  if (left.info() != Eigen::Success) return;
  const Matrix pencil = left.solve(G.transpose() * (Vhat.transpose() * W));
  if (!pencil.allFinite()) return;
  const Eigen::EigenSolver<Matrix> eig(pencil);
  if (eig.info() != Eigen::Success) return;
  const Eigen::VectorXcd lambda = eig.eigenvalues();
  const Eigen::MatrixXcd vectors = eig.eigenvectors();  // formed once (each call builds it)
  std::vector<Index> order(static_cast<std::size_t>(dim));
  std::iota(order.begin(), order.end(), Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) {
    return std::abs(lambda(a)) > std::abs(lambda(b));
  });
  const Index wanted = std::min<Index>(s.size, dim);
  Matrix P(dim, wanted);
  Index taken = 0;
  std::vector<bool> done(static_cast<std::size_t>(dim), false);
  for (const Index i : order) {
    if (done[static_cast<std::size_t>(i)] || taken >= wanted) continue;
    const Eigen::VectorXcd z = vectors.col(i);
    if (lambda(i).imag() == 0) {
      P.col(taken++) = z.real();
    } else {
      if (taken + 2 > wanted) break;
      P.col(taken++) = z.real();
      P.col(taken++) = z.imag();
      // Its conjugate spans the same two columns.
      for (Index j = 0; j < dim; ++j) {
        if (!done[static_cast<std::size_t>(j)] && j != i &&
            std::abs(lambda(j) - std::conj(lambda(i))) <= 1e-12 * std::abs(lambda(i))) {
          done[static_cast<std::size_t>(j)] = true;
          break;
        }
      }
    }
    done[static_cast<std::size_t>(i)] = true;
  }
  if (taken == 0) return;
  const Eigen::HouseholderQR<Matrix> pq(P.leftCols(taken));
  const Matrix Pk = pq.householderQ() * Matrix::Identity(dim, taken);
  const Eigen::HouseholderQR<Matrix> gq(G * Pk);
  const Matrix R = gq.matrixQR().topLeftCorner(taken, taken).triangularView<Eigen::Upper>();
  const double largest = R.diagonal().cwiseAbs().maxCoeff();
  if (!(largest > 0) || R.diagonal().cwiseAbs().minCoeff() <= 1e-8 * largest) return;
  Matrix C = Vhat * (gq.householderQ() * Matrix::Identity(dim + 1, taken));
  Matrix U = R.triangularView<Eigen::Upper>().solve<Eigen::OnTheRight>(W * Pk);
  if (!C.allFinite() || !U.allFinite()) return;
  s.C = std::move(C);
  s.U = std::move(U);
}

}  // namespace gmres_detail

// Solves A x = b to |b − A x| <= tolerance |b| from x = 0, with at most `restarts` + 1 cycles of
// `dimension` products (GCRO-DR's cycles: `dimension` less the vectors kept), recycling through
// `recycled` where it is given with a nonzero size smaller than `dimension`. Returns what it
// reached.
inline GmresResult gmres(const std::function<Vector(const Vector&)>& apply, const Vector& b,
                         Vector& x, double tolerance, int dimension, int restarts,
                         RecycledSubspace* recycled = nullptr) {
  GmresResult result;
  const Index n = b.size();
  x = Vector::Zero(n);
  const double b_norm = b.norm();
  if (b_norm == 0) return result;
  const bool recycling = recycled != nullptr && recycled->size > 0 &&
                         recycled->size < dimension && recycled->size < n;
  if (recycling && (recycled->U.rows() != n || recycled->C.rows() != n)) recycled->clear();
  if (recycling && recycled->U.cols() > 0 && !recycled->current) {
    result.products += gmres_detail::form_recycled_image(apply, *recycled);
  }
  const auto kept = [&]() -> Index { return recycling ? recycled->U.cols() : 0; };
  Vector r = b;
  bool projected = false;  // r is b − C Cᵀ b, which equals b − A x only where A U = C exactly
  if (kept() > 0) {
    const Vector c = recycled->C.transpose() * b;
    x = recycled->U * c;
    r = b - recycled->C * c;
    projected = true;
  }
  for (int cycle = 0; cycle <= restarts; ++cycle) {
    result.relative_residual = r.norm() / b_norm;
    if (result.relative_residual <= tolerance && projected) {
      // The projection alone claims the tolerance: the true residual decides.
      r = b - apply(x);
      ++result.products;
      result.relative_residual = r.norm() / b_norm;
    }
    projected = false;
    if (result.relative_residual <= tolerance) break;
    const Index k = kept();
    Vector c;
    Vector start = r;
    if (k > 0) {
      c = recycled->C.transpose() * r;
      start -= recycled->C * c;
    }
    const double beta = start.norm();
    const int m = static_cast<int>(std::max<Index>(1, std::min<Index>(dimension - k, n - k)));
    Matrix V = Matrix::Zero(n, m + 1);
    Matrix H = Matrix::Zero(m + 1, m);
    Matrix Hraw, B = Matrix::Zero(k, m);  // H before its rotations, and Cᵀ A V: for recycling
    if (recycling) Hraw = Matrix::Zero(m + 1, m);
    std::vector<double> cs(m), sn(m);
    Vector g = Vector::Zero(m + 1);
    g(0) = beta;
    int used = 0;
    if (beta > 0) {
      V.col(0) = start / beta;
      for (int j = 0; j < m; ++j) {
        Vector w = apply(V.col(j));
        ++result.products;
        for (int pass = 0; pass < 2; ++pass) {
          for (Index i = 0; i < k; ++i) {
            const double h = recycled->C.col(i).dot(w);
            B(i, j) += h;
            w -= h * recycled->C.col(i);
          }
          for (int i = 0; i <= j; ++i) {
            const double h = V.col(i).dot(w);
            H(i, j) += h;
            w -= h * V.col(i);
          }
        }
        H(j + 1, j) = w.norm();
        if (H(j + 1, j) > 0) V.col(j + 1) = w / H(j + 1, j);
        if (recycling) Hraw.col(j) = H.col(j);
        // Givens rotations keep H upper triangular; |g(j+1)| is the residual norm (the part along
        // C is solved exactly below).
        for (int i = 0; i < j; ++i) {
          const double t = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
          H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
          H(i, j) = t;
        }
        const double denom = std::hypot(H(j, j), H(j + 1, j));
        cs[j] = denom == 0 ? 1.0 : H(j, j) / denom;
        sn[j] = denom == 0 ? 0.0 : H(j + 1, j) / denom;
        H(j, j) = denom;
        H(j + 1, j) = 0;
        g(j + 1) = -sn[j] * g(j);
        g(j) = cs[j] * g(j);
        // A zero pivot (the projected operator singular along V's last column, as it is along
        // span U ∩ C⊥) leaves that column out of the solution.
        used = H(j, j) == 0 ? j : j + 1;
        if (std::abs(g(j + 1)) / b_norm <= tolerance || H(j, j) == 0) break;
      }
    }
    const Vector y =
        H.topLeftCorner(used, used).triangularView<Eigen::Upper>().solve(g.head(used));
    x += V.leftCols(used) * y;
    // Along C: U (Cᵀ r − B y), which leaves no residual there.
    if (k > 0) x += recycled->U * (c - B.leftCols(used) * y);
    r = b - apply(x);
    ++result.products;
    result.relative_residual = r.norm() / b_norm;
    if (recycling && used > 0) {
      if (k == 0) {
        recycled->U.resize(n, 0);
        recycled->C.resize(n, 0);
      }
      gmres_detail::update_recycled(*recycled, V, Hraw, B, used);
    }
  }
  if (recycling && recycled->U.cols() > 0) recycled->current = true;
  return result;
}

}  // namespace pwl::orbits::detail
