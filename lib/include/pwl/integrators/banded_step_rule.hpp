#pragma once
// The paper's step-selection rule for periodic structures (He, Gao & Zhong 2018, §2; SPEC.md §4):
// the step is the one within which energy does not travel more than q cells, η = min(η1, η2).
//
// Given the wished-for step η1 and the cell count q, the 2^N algorithm is run on substructures
// that reach q + guard degrees of freedom beyond a row on each side, starting from τ0 = η1/2^N.
// Each doubling doubles the time covered. After each one the entries of the row more than q
// away are watched: when, in some block of T relative to that block's row sum, they first
// exceed the tolerance (after doubling number N̄), the energy has left the band, and the step
// goes back one doubling, η = τ0·2^(N̄-1), whose exponential was the previous one. If that never
// happens, η = η1. (The paper prints η2 = 2^(N̄-1) η1 with η1 standing for τ0.)
//
// The paper watches one substructure of 2q+1 cells; here every distinct substructure of the
// structure is watched (rows near the ends, and every cell when cells differ), each computed
// once when its content repeats, and the guard cells make the entries beyond q exist to be
// watched. The tail measure is that of banded_exponential.hpp per row, so the band q meets the
// same tolerance for T at the chosen step (the load integrals fall off faster than T).
#include <string>
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/numerics/precise_exponential.hpp"

namespace pwl {

struct BandedStepRuleOptions {
  double wished_step = 0.0;  // η1 > 0
  Index band = 5;            // q: degrees of freedom the energy may cross in one step (paper: 5,
                             // its 11-dof substructure)
  double tolerance = 1e-15;  // entries beyond q, relative to their block's row sum
  Index guard = 1;           // watched distances q+1 .. q+guard
  PreciseExponentialOptions exponential;  // N (doublings) and the Taylor order
  bool is_valid(std::string* why) const;
};

struct BandedStepChoice {
  double step = 0.0;         // η = min(η1, η2)
  double wished_step = 0.0;  // η1
  double start_step = 0.0;   // τ0 = η1 / 2^N
  Index band = 0;            // q
  int doublings = 0;         // N
  int exceeded_after = -1;   // N̄, or -1 when the energy never left the band (η = η1)
  // Largest watched ratio over the substructures after each doubling d = 0..N (d = 0: the
  // Taylor start at τ0); the step after doubling d is τ0·2^d.
  std::vector<double> leaked;
  double leaked_at_step = 0.0;  // the ratio at the chosen step
  Index substructures = 0;      // distinct substructures watched
};

// Throws InputError for invalid options or structure, a mass matrix that is not diagonal, or a
// band so small that the energy leaves it within τ0 already.
BandedStepChoice select_banded_step(const GapStructure& structure,
                                    const BandedStepRuleOptions& options);

}  // namespace pwl
