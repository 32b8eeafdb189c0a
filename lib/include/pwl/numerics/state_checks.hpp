#pragma once
// The checks every integrator makes of the state it is given and of the state it reaches, in one
// place so that they and their messages agree: the sizes and finiteness of an initial state
// (set_state), and the divergence bound of a running one.
#include <string>
#include <string_view>

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

// The part of an options struct's is_valid that every fixed-step integrator shares: a positive,
// finite step and a positive divergence bound. False with the message naming the field and value.
bool check_step_settings(double step, double divergence_bound, std::string* why);

// A nested options check (`valid`, with its message in *why) prefixed with its field: "band.q = ...".
bool check_nested(bool valid, std::string_view field, std::string* why);

}  // namespace pwl
