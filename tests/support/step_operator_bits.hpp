#pragma once
// Bit-for-bit comparison of banded step operators: construction from the period against the
// row-by-row build (lib/src/banded/periodic_cut.hpp), for the tests that check it.
#include <catch2/catch.hpp>
#include <cstring>

#include "pwl/integrators/banded_step_operators.hpp"

namespace pwl::test {

// Same shape and the same entries, bit for bit (the sign of a zero and a NaN count).
inline bool same_bits(const BandedMatrix& a, const BandedMatrix& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  const Matrix da = a.to_dense(), db = b.to_dense();
  return std::memcmp(da.data(), db.data(), sizeof(double) * static_cast<std::size_t>(da.size())) ==
         0;
}

inline bool same_bits(const Vector& a, const Vector& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

// The operators laid out from the period (`laid_out`) against those built row by row.
inline void check_same_step_operators(const BandedStepOperators& laid_out,
                                      const BandedStepOperators& built) {
  const BandedStepOperators& a = laid_out;
  const BandedStepOperators& b = built;
  CHECK(b.truncation.laid_out == 0);
  CHECK(a.truncation.band == b.truncation.band);
  CHECK(a.truncation.blocks == b.truncation.blocks);
  CHECK(same_bits(a.transition, b.transition));
  CHECK(same_bits(a.force_now, b.force_now));
  CHECK(same_bits(a.force_next, b.force_next));
  CHECK(same_bits(a.lcp_matrix, b.lcp_matrix));
  REQUIRE(a.harmonics.size() == b.harmonics.size());
  for (std::size_t g = 0; g < a.harmonics.size(); ++g) {
    CHECK(a.harmonics[g].omega == b.harmonics[g].omega);
    CHECK(same_bits(a.harmonics[g].sin_response, b.harmonics[g].sin_response));
    CHECK(same_bits(a.harmonics[g].cos_response, b.harmonics[g].cos_response));
  }
  CHECK(a.spring_order == b.spring_order);
  CHECK(same_bits(a.gaps, b.gaps));
  // Shared rows: the long chain's distinct rows are the short chain's.
  CHECK(a.transition.stored_rows() == b.transition.stored_rows());
}

}  // namespace pwl::test
