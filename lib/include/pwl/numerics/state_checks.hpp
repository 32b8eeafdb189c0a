#pragma once
// The checks every integrator makes of the state it is given and of the state it reaches, in one
// place so that they and their messages agree: the sizes and finiteness of an initial state
// (set_state), and the divergence bound of a running one.
#include "pwl/types.hpp"

namespace pwl {

// Throws InputError unless x and v both have n entries and t, x and v are finite; the message
// names the sizes, or the first entry that is not finite.
void check_initial_state(double t, const Eigen::Ref<const Vector>& x,
                         const Eigen::Ref<const Vector>& v, Index n);

// Throws the DivergenceError of a state at time t whose largest |x| or |x'| is `largest` (NaN
// when the state is not finite), beyond `bound`. The test itself, !(largest <= bound), stays in
// each stepper's loop, where it costs one comparison.
[[noreturn]] void throw_divergence(double t, double largest, double bound);

}  // namespace pwl
