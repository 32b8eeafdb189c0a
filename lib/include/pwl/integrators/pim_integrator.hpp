#pragma once
// The precise-integration method behind the Integrator concept: picks a fixed-size
// PrecisePropagator for small structures and the run-time-sized one otherwise.
#include <memory>
#include <string>

#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/numerics/lcp_solver.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

struct PimOptions {
  double step = 0.0;                         // η > 0
  LcpAlgorithm lcp_solver = LcpAlgorithm::block_pivoting;
  PreciseExponentialOptions exponential;     // N and the Taylor order
  double divergence_bound = 1e12;            // |x|, |x'| beyond this is a DivergenceError
  bool is_valid(std::string* why) const;
};

// Throws InputError for an invalid structure or options.
std::unique_ptr<Integrator> make_pim_integrator(const GapStructure& structure,
                                                const PimOptions& options);

}  // namespace pwl
