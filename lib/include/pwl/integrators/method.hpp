#pragma once
// The integrators pwl ships, as one enum. Everything else about a method (its name on the command
// line, its label in tables and figures, what it can do) is a row of the method table
// (method_table.hpp); code asks that row, never a name.
namespace pwl {

enum class Method {
  pim,                   // the paper's PIM, dense or banded by the structure's size and layout
  pim_dense,             // the PIM with dense operators (fixed-size for up to 6 masses)
  pim_banded,            // the PIM with banded operators (long chains)
  pim_switching,         // the higher-order switching PIM, dense or banded by size and layout
  pim_switching_dense,   // the switching PIM with dense operators
  pim_switching_banded,  // the switching PIM with banded operators
  exact,                 // the exact event-driven solver (small structures)
  dopri5,                // Dormand-Prince 5(4) (Boost.Odeint), plain or kink-located
  rkf78,                 // Runge-Kutta-Fehlberg 7(8) (Boost.Odeint), plain or kink-located
};

}  // namespace pwl
