#pragma once
// Errors pwl reports. Every message names the offending field and its value, so that a user can
// fix the input without reading the source.
#include <stdexcept>
#include <string>

namespace pwl {

// Base of every pwl error.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The input is wrong: a negative mass, a NaN, a matrix of the wrong size, a zero step.
class InputError : public Error {
 public:
  using Error::Error;
};

// A linear complementarity problem has no solution the solver can reach (ray termination,
// a matrix that is not a P-matrix, an iteration limit).
class LcpError : public Error {
 public:
  using Error::Error;
};

// The motion left every reasonable bound (a non-finite state, or one beyond a stated limit).
class DivergenceError : public Error {
 public:
  using Error::Error;
};

// A computation spent the work budget it was given (the event-driven solver's switches or gap
// evaluations in one call): the input is valid, but this method would take too long on it. The
// message names the budget, how far the computation got and what to do instead.
class BudgetError : public Error {
 public:
  using Error::Error;
};

}  // namespace pwl
