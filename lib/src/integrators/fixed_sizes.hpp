#pragma once
// How many square gap structures (n masses, one gap spring each: n = 1 .. kFixedSizes) get a
// stepper of fixed-size Eigen types of their own, in the dense PIM (pim_integrator.cpp) and the
// dense switching PIM (switching_pim.cpp); every other structure takes the dynamic-size stepper,
// the same template. Each fixed size is a whole instantiation of the stepper, the heaviest code
// the library compiles: the build option PWL_FIXED_SIZES (top-level CMakeLists.txt) sets the
// count, 6 by default. The sanitizer build takes 2: the template's code still runs there at fixed
// sizes (1 and 2) and at the dynamic size (the compiler time it saves: apps/README.md, "How the
// build is kept short"). Private to pwl_core.
#ifndef PWL_FIXED_SIZES
#define PWL_FIXED_SIZES 6
#endif

namespace pwl::detail {

inline constexpr int kFixedSizes = PWL_FIXED_SIZES;
static_assert(kFixedSizes >= 0 && kFixedSizes <= 6, "PWL_FIXED_SIZES must be in 0 .. 6");

}  // namespace pwl::detail
