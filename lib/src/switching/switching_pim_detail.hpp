#pragma once
// Pieces shared by the dense and the banded higher-order PIM (switching_pim.hpp,
// banded_switching_pim.hpp); private to pwl_core.
#include <algorithm>
#include <cmath>

#include "event/event_location.hpp"
#include "pwl/types.hpp"

namespace pwl::switching_detail {

// The gap functions of one piece of a switching step as polynomials in σ = s/h on [0, 1]:
// e_j(σ) = Σ_r c(j, r) σ^r (mode-signed).
class PolynomialGaps final : public event_detail::ModeGaps {
 public:
  Matrix c;  // m x (R+1)
  Index springs() const override { return c.rows(); }

  void sample(const event_detail::GapSample&, double s, event_detail::GapSample& out) override {
    const Index m = c.rows();
    const Index R = c.cols() - 1;
    out.t = s;
    out.e.resize(m);
    out.rate.resize(m);
    out.accel.resize(m);
    for (Index j = 0; j < m; ++j) {
      double e = c(j, R), r = 0.0, a = 0.0;
      for (Index k = R - 1; k >= 0; --k) {
        a = a * s + 2.0 * r;
        r = r * s + e;
        e = e * s + c(j, k);
      }
      out.e[j] = e;
      out.rate[j] = r;
      out.accel[j] = a;
    }
  }

  void derivative_bound(const event_detail::GapSample& from, double span, int order, Vector& bound) override {
    const double top = std::max(0.0, from.t + span);
    const Index R = c.cols() - 1;
    bound = Vector::Zero(c.rows());
    double power = 1.0;  // top^(r - order)
    for (Index r = order; r <= R; ++r) {
      double f = power;  // r!/(r-order)! top^(r-order)
      for (int i = 0; i < order; ++i) f *= static_cast<double>(r - i);
      bound += f * c.col(r).cwiseAbs();
      power *= top;
    }
  }

  void sample_spring(const event_detail::GapSample&, double s, Index j, double* value, double* rate) override {
    const Index R = c.cols() - 1;
    double e = c(j, R), r = 0.0;
    for (Index k = R - 1; k >= 0; --k) {
      r = r * s + e;
      e = e * s + c(j, k);
    }
    *value = e;
    *rate = r;
  }

  void spring_derivatives(const event_detail::GapSample& at, Index j, int max_order, double* d) override {
    const Index R = c.cols() - 1;
    for (int q = 0; q <= max_order; ++q) {
      double sum = 0.0, power = 1.0;
      for (Index r = q; r <= R; ++r) {
        double f = power;
        for (int i = 0; i < q; ++i) f *= static_cast<double>(r - i);
        sum += f * c(j, r);
        power *= at.t;
      }
      d[q] = sum;
    }
  }

  double spring_derivative_bound(const event_detail::GapSample& from, double span, int order,
                                 Index j) override {
    const double top = std::max(0.0, from.t + span);
    const Index R = c.cols() - 1;
    double sum = 0.0, power = 1.0;
    for (Index r = order; r <= R; ++r) {
      double f = power;
      for (int i = 0; i < order; ++i) f *= static_cast<double>(r - i);
      sum += f * std::abs(c(j, r));
      power *= top;
    }
    return sum;
  }

  void derivatives(const event_detail::GapSample& at, int max_order, Matrix& d) override {
    const Index R = c.cols() - 1;
    d = Matrix::Zero(c.rows(), max_order + 1);
    for (int q = 0; q <= max_order; ++q) {
      double power = 1.0;  // at.t^(r - q)
      for (Index r = q; r <= R; ++r) {
        double f = power;
        for (int i = 0; i < q; ++i) f *= static_cast<double>(r - i);
        d.col(q) += f * c.col(r);
        power *= at.t;
      }
    }
  }
};
}  // namespace pwl::switching_detail
