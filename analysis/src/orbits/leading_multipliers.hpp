#pragma once
// The leading multipliers of a matrix-free orbit, by the method the options and the structure
// allow: Davidson preconditioned by the open structure's shifted inverse where that is available
// (classical damping) and ArnoldiOptions::method is automatic, thick-restarted Arnoldi otherwise
// (pwl/orbits/floquet_multipliers.hpp says why: a long chain's crowd of long waves round the
// circle, which Arnoldi separates only with a basis as large as the crowd).
#include "orbits/open_structure_preconditioner.hpp"
#include "pwl/orbits/floquet_multipliers.hpp"

namespace pwl::orbits::detail {

inline FloquetMultipliers leading_multipliers(const std::function<void(Matrix&)>& apply,
                                              Index size, const ArnoldiOptions& options,
                                              const OpenStructurePreconditioner* open,
                                              const Eigen::MatrixXcd* warm = nullptr,
                                              Eigen::MatrixXcd* vectors = nullptr) {
  if (open != nullptr && open->available() && options.method == ArnoldiOptions::Method::automatic) {
    return preconditioned_floquet_multipliers(
        apply,
        [open](const Eigen::VectorXcd& r, std::complex<double> sigma) {
          return open->shifted_inverse(r, sigma);
        },
        size, options, warm, vectors);
  }
  return leading_floquet_multipliers(apply, size, options, warm, vectors);
}

}  // namespace pwl::orbits::detail
