# Bad values everywhere (issue 15): every numeric flag of every job, typed or as a scene key,
# refuses NaN, ±Inf and a value outside its sign or range with exit code 2 and a message naming
# the flag and the value. One table, bad_values.csv, drives bad_values_test.cpp (a Catch2 program
# of this folder, globbed with the others): it builds the program's command line as main.cpp does,
# fails for a numeric flag without rows, and runs the real program on every row, a few at a time,
# each with a time limit (under AddressSanitizer one row per job and flag, cycling through the
# kinds of bad value: see rows_to_run()).
target_link_libraries(bad_values_test PRIVATE pwl_bench pwl_app)
target_compile_definitions(bad_values_test PRIVATE
                           PWL_EXECUTABLE="$<TARGET_FILE:pwl>"
                           PWL_BAD_VALUES_TABLE="${CMAKE_CURRENT_SOURCE_DIR}/bad_values.csv")
add_dependencies(bad_values_test pwl)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
             ${CMAKE_CURRENT_SOURCE_DIR}/bad_values.csv)

# Secular growth is unbounded: the undamped linear resonance of issue 15 (one mass, no contact
# stiffness, no damping, forced at its natural frequency from rest: x = t sin(t) / 2, amplitude
# ∝ t), which was called quasi-periodic, is classified unbounded, and the rule says what grew how.
add_test(NAME cli_analyze_undamped_resonance_unbounded
         COMMAND pwl analyze --n 1 --alpha 0 --zeta 0 --theta 1 --loads 1
                 --out ${PWL_CLI_OUT}/undamped_resonance)
set_tests_properties(cli_analyze_undamped_resonance_unbounded PROPERTIES
                     PASS_REGULAR_EXPRESSION "regime: unbounded.*rule: unbounded: the amplitude grows like t\\^1\\.00 over the record"
                     FAIL_REGULAR_EXPRESSION "pwl: |quasi-periodic"
                     ENVIRONMENT "PWL_PLOTS_DIR=${PROJECT_SOURCE_DIR}/plots")
# Detuned (θ = 0.97), the same mass beats with a bounded envelope: not unbounded. The beat is
# exactly periodic: 97 forcing periods are 100 free periods, beyond the period search's 64, and
# orbit refinement (the evidence ladder) finds the motion on a period-97 orbit (neutral: |μ| = 1,
# no damping).
add_test(NAME cli_analyze_undamped_beating_bounded
         COMMAND pwl analyze --n 1 --alpha 0 --zeta 0 --theta 0.97 --loads 1
                 --out ${PWL_CLI_OUT}/undamped_beating)
set_tests_properties(cli_analyze_undamped_beating_bounded PROPERTIES
                     PASS_REGULAR_EXPRESSION "regime: period-97.*Newton: minimal period 97, leading [^\n]* = 1 at that period; the motion is on it"
                     FAIL_REGULAR_EXPRESSION "pwl: |unbounded"
                     ENVIRONMENT "PWL_PLOTS_DIR=${PROJECT_SOURCE_DIR}/plots")
