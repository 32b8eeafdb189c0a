#pragma once
// Restarted GMRES for A x = b with A known only by its products (Y. Saad and M. H. Schultz, SIAM J.
// Sci. Stat. Comput. 7 (1986) 856-869): the Krylov solver of matrix-free Newton on the
// stroboscopic map of a long chain. Private to the orbits room.
#include <cmath>
#include <functional>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::orbits::detail {

struct GmresResult {
  double relative_residual = 0.0;  // |b − A x| / |b|
  int products = 0;                // products with A
};

// Solves A x = b to |b − A x| <= tolerance |b| from x = 0, with at most `restarts` + 1 cycles of
// `dimension` products. Returns what it reached.
inline GmresResult gmres(const std::function<Vector(const Vector&)>& apply, const Vector& b,
                         Vector& x, double tolerance, int dimension, int restarts) {
  GmresResult result;
  const Index n = b.size();
  x = Vector::Zero(n);
  const double b_norm = b.norm();
  if (b_norm == 0) return result;
  Vector r = b;
  for (int cycle = 0; cycle <= restarts; ++cycle) {
    const double beta = r.norm();
    result.relative_residual = beta / b_norm;
    if (result.relative_residual <= tolerance) return result;
    const int m = static_cast<int>(std::min<Index>(dimension, n));
    Matrix V = Matrix::Zero(n, m + 1);
    Matrix H = Matrix::Zero(m + 1, m);
    std::vector<double> cs(m), sn(m);
    Vector g = Vector::Zero(m + 1);
    g(0) = beta;
    V.col(0) = r / beta;
    int used = 0;
    for (int j = 0; j < m; ++j) {
      Vector w = apply(V.col(j));
      ++result.products;
      for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i <= j; ++i) {
          const double h = V.col(i).dot(w);
          H(i, j) += h;
          w -= h * V.col(i);
        }
      }
      H(j + 1, j) = w.norm();
      if (H(j + 1, j) > 0) V.col(j + 1) = w / H(j + 1, j);
      // Givens rotations keep H upper triangular; |g(j+1)| is the residual norm.
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
      used = j + 1;
      if (std::abs(g(j + 1)) / b_norm <= tolerance || H(j, j) == 0) break;
    }
    const Vector y = H.topLeftCorner(used, used).triangularView<Eigen::Upper>().solve(g.head(used));
    x += V.leftCols(used) * y;
    r = b - apply(x);
    ++result.products;
    result.relative_residual = r.norm() / b_norm;
  }
  return result;
}

}  // namespace pwl::orbits::detail
