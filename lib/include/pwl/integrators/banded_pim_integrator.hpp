#pragma once
// The banded precise-integration method behind the Integrator concept (He, Gao & Zhong 2018;
// Zhong & Williams 1994): the same interface as make_pim_integrator, so `pwl simulate` and the
// analysis code use it unchanged, with work and memory per step O(n q) instead of O(n²).
//
// A structure qualifies when its mass matrix is diagonal and M, C, K and the springs couple only
// degrees of freedom a few apart: the bandwidths are read from the sparse structure
// (banded_layout). Whether its cells repeat (so that a few substructures give the whole band) is
// detected, or declared through BandedExponentialOptions::cell_dofs.
#include <memory>
#include <string>

#include "pwl/numerics/banded_exponential.hpp"
#include "pwl/numerics/banded_lcp_solver.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/pim_integrator.hpp"

namespace pwl {

struct BandedPimOptions {
  double step = 0.0;                    // η > 0
  BandedExponentialOptions band;        // tolerance (or a forced band q), substructures, N
  BandedLcpOptions lcp;
  double divergence_bound = 1e12;       // |x|, |x'| beyond this is a DivergenceError
  bool is_valid(std::string* why) const;
};

// How banded a structure is, read from its sparse matrices and springs.
struct BandedLayout {
  bool diagonal_mass = false;
  Index dof_bandwidth = 0;     // max |i - j| over the non-zeros of C and K
  Index spring_reach = 0;      // max |dof - other_dof| over the springs between two dofs
  Index cell_dofs = 0;         // detected period of M, C and K (0: none)
  // Whether the banded method applies and pays: diagonal mass, and every coupling short
  // compared with the structure (2 · max(dof_bandwidth, spring_reach) < dofs / 4).
  bool banded = false;
  std::string why_not;         // when not banded
};
BandedLayout banded_layout(const GapStructure& structure);

// The banded stepper, whatever the size (it stays exact to the truncation for any structure with
// a diagonal mass matrix; it only pays when the structure is banded). Throws InputError for
// invalid options or structure, or a mass matrix that is not diagonal.
std::unique_ptr<Integrator> make_banded_pim_integrator(const GapStructure& structure,
                                                       const BandedPimOptions& options);

// Dense or banded by size: the banded stepper when the structure has more than banded_above
// degrees of freedom and banded_layout says it is banded, the dense one otherwise. The step,
// the divergence bound and the most doublings come from `options`; the banded stepper keeps its
// substructures' own series order and trimmed doublings (BandedExponentialOptions), so that it is
// the stepper make_banded_pim_integrator gives. `options`' lcp_solver applies to the dense stepper
// only (the banded one uses BandedLcpSolver).
std::unique_ptr<Integrator> make_pim_integrator_auto(const GapStructure& structure,
                                                     const PimOptions& options,
                                                     Index banded_above = 50);

}  // namespace pwl
