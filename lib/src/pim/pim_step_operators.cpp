#include "pwl/integrators/pim_step_operators.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {

Matrix state_matrix(const GapStructure& structure) {
  const Index n = structure.dofs();
  const Eigen::LLT<Matrix> mass(Matrix(structure.mass));
  Matrix H = Matrix::Zero(2 * n, 2 * n);
  H.topRightCorner(n, n).setIdentity();
  H.bottomLeftCorner(n, n) = -mass.solve(Matrix(structure.stiffness));
  H.bottomRightCorner(n, n) = -mass.solve(Matrix(structure.damping));
  return H;
}

PimStepOperators make_pim_step_operators(const GapStructure& structure, double step,
                                         const PreciseExponentialOptions& options) {
  structure.validate();
  if (!std::isfinite(step) || step <= 0.0) {
    throw InputError(fmt::format("step = {} must be positive and finite", step));
  }
  const Index n = structure.dofs();
  const Index m = structure.spring_count();
  const Eigen::LLT<Matrix> mass(Matrix(structure.mass));
  const Matrix H = state_matrix(structure);

  PimStepOperators ops;
  ops.step = step;
  ops.directions = structure.spring_directions();
  ops.gaps = structure.spring_gaps();
  ops.stiffnesses = structure.spring_stiffnesses();

  // Spring forces enter as -W P: in state space G = [0; -M⁻¹W].
  Matrix G = Matrix::Zero(2 * n, m);
  if (m > 0) G.bottomRows(n) = -mass.solve(ops.directions);

  // Each load group contributes two columns, sin_part and cos_part, at its frequency.
  const std::vector<LoadGroup> groups = structure.load_groups();
  const Index h = static_cast<Index>(groups.size());
  Matrix B = Matrix::Zero(2 * n, 2 * h);
  Vector omegas(2 * h);
  for (Index g = 0; g < h; ++g) {
    const LoadGroup& group = groups[static_cast<std::size_t>(g)];
    B.col(2 * g).bottomRows(n) = mass.solve(group.sin_part);
    B.col(2 * g + 1).bottomRows(n) = mass.solve(group.cos_part);
    omegas[2 * g] = omegas[2 * g + 1] = group.omega;
  }

  const PreciseExponential e = precise_exponential(H, step, G, B, omegas, options);
  ops.transition = e.transition;
  ops.force_now = e.gamma1 / step;
  ops.force_next = e.gamma0 - ops.force_now;
  // ∫ e^{H(η-s)} b sin(ω(t_k+s)) ds = Im(e^{iωt_k} K b); the cos load is the real part.
  for (Index g = 0; g < h; ++g) {
    HarmonicResponse r;
    r.omega = groups[static_cast<std::size_t>(g)].omega;
    r.sin_response = e.harmonic_real.col(2 * g) - e.harmonic_imag.col(2 * g + 1);
    r.cos_response = e.harmonic_imag.col(2 * g) + e.harmonic_real.col(2 * g + 1);
    ops.harmonics.push_back(std::move(r));
  }
  ops.lcp_matrix = Matrix::Identity(m, m) -
                   ops.stiffnesses.asDiagonal() * ops.directions.transpose() *
                       ops.force_next.topRows(n);
  return ops;
}

}  // namespace pwl
