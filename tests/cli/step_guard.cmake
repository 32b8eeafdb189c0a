# Answers that are trustworthy or refused (included by tests/cli/CMakeLists.txt): one test per row
# of the table that opened this work, and the step guard in every job that integrates.
#
# Row 1: a NaN parameter is refused naming the flag (the generated table in bad_values.csv checks
# every numeric flag of every job; this is the row as a user first met it).
add_test(NAME cli_simulate_theta_nan_refused
         COMMAND sh -c "out=$(\"$<TARGET_FILE:pwl>\" simulate --theta nan --out ${PWL_CLI_OUT}/theta_nan 2>&1); code=$?; echo \"$out\"; test $code -eq 2 && echo \"$out\" | grep -qF -- '--theta: must be a finite number, got nan' && test ! -e ${PWL_CLI_OUT}/theta_nan/poincare.csv")
# Row 2: the PIM at T/20 on a contact of α = 1e9 (η ω_max = 9.9e3, where the motion it returned
# grew to |x| = 650 while the exact motion stays below 2) is refused before anything is written,
# with the step that would do; --force runs it with the refusal as a warning; a step between the
# warning and the refusal limits (α = 100, T/64: η ω_max = 1.0) runs with a warning.
add_test(NAME cli_simulate_stiff_step_refused
         COMMAND sh -c "out=$(\"$<TARGET_FILE:pwl>\" simulate --n 5 --alpha 1e9 --steps-per-period 20 --periods 20 --out ${PWL_CLI_OUT}/stiff_refused 2>&1); code=$?; echo \"$out\"; test $code -eq 2 && test ! -e ${PWL_CLI_OUT}/stiff_refused/poincare.csv && echo \"$out\" | grep -qF -- 'use a step of at most 1.58e-05 (η ω_max = 0.5), 397384 steps per forcing period'")
set_tests_properties(cli_simulate_stiff_step_refused PROPERTIES PASS_REGULAR_EXPRESSION
                     "pwl: bad input: pim: step = 0.314 is too long for the stiffest contact: η ω_max = 9.93e\\+03 \\(ω_max = 3.16e\\+04.*exceeds the PIM's limit 1.57.*--force runs it anyway")
add_test(NAME cli_simulate_stiff_step_forced
         COMMAND sh -c "\"$<TARGET_FILE:pwl>\" simulate --n 5 --alpha 1e9 --steps-per-period 20 --periods 2 --force --quiet --out ${PWL_CLI_OUT}/stiff_forced 2>&1 && test $(wc -l < ${PWL_CLI_OUT}/stiff_forced/poincare.csv) -eq 4")
set_tests_properties(cli_simulate_stiff_step_forced PROPERTIES PASS_REGULAR_EXPRESSION
                     "pwl: warning: pim: step = 0.314 is too long.*\\(run anyway: --force\\)")
add_test(NAME cli_simulate_step_warning
         COMMAND sh -c "\"$<TARGET_FILE:pwl>\" simulate --n 5 --alpha 100 --steps-per-period 64 --periods 2 --quiet --out ${PWL_CLI_OUT}/step_warning 2>&1 && test $(wc -l < ${PWL_CLI_OUT}/step_warning/poincare.csv) -eq 4")
set_tests_properties(cli_simulate_step_warning PROPERTIES
                     PASS_REGULAR_EXPRESSION "pwl: warning: pim: step = 0.0982 resolves the stiffest contact poorly: η ω_max = 1 .*use a step of at most 0.0491"
                     FAIL_REGULAR_EXPRESSION "run anyway")
# Every job that integrates a case judges its step the same way: analyze, orbit and continue (at
# either end of its range), sweep and map (every point, before the first is computed; nothing is
# written); the switching PIM by its own limit.
foreach(job "analyze --n 5 --alpha 1e9 --steps-per-period 20|pim: step = 0.314 is too long"
            "orbit --n 5 --alpha 1e9 --method pim --steps-per-period 20|pim: step = 0.314 is too long"
            "orbit --n 5 --alpha 1e9 --method pim-switching --steps-per-period 20|pim-switching: step = 0.314 is too long"
            "continue --n 5 --method pim --parameter alpha --range 5:1e9 --steps-per-period 200|pim: step = 0.0314 is too long"
            "sweep --n 5 --parameter alpha --range 1:1e9 --points 5 --steps-per-period 50|the step guard refuses 4 of the 5 points of this study (--steps-per-period 397384 or more satisfies every point)"
            "map --n 5 --x alpha --x-range 1:1e9 --x-points 3 --y theta --y-range 0.5:2 --y-points 2 --steps-per-period 50|the step guard refuses 4 of the 6 points of this study")
  string(REPLACE "|" ";" parts "${job}")
  list(GET parts 0 flags)
  list(GET parts 1 message)
  string(REGEX MATCH "^[a-z]+" command "${flags}")
  string(REPLACE " " "_" name "${flags}")
  string(REGEX REPLACE "[^A-Za-z0-9_]" "" name "${name}")
  string(SUBSTRING "${name}" 0 60 name)
  add_test(NAME cli_step_guard_${name}
           COMMAND sh -c "rm -rf ${PWL_CLI_OUT}/guard_${name}; out=$(\"$<TARGET_FILE:pwl>\" ${flags} --out ${PWL_CLI_OUT}/guard_${name} 2>&1); code=$?; echo \"$out\"; test $code -eq 2 && echo \"$out\" | grep -qF -- '${message}' && test ! -e ${PWL_CLI_OUT}/guard_${name}")
endforeach()
# Row 3: the exact solver on the same α = 1e9 contact finishes 20 periods (it took more than ten
# minutes before its stiff contacts were settled in closed form), stays bounded, and agrees with
# kink-located rkf78 at 1e-13 over 5 periods (measured 7e-9; 2e-7 at 1e-11, 2e-9 at 1e-13: the
# reference converges onto it).
add_test(NAME cli_simulate_exact_stiff_contact
         COMMAND sh -c "\"$<TARGET_FILE:pwl>\" simulate --n 5 --alpha 1e9 --method exact --periods 20 --quiet --out ${PWL_CLI_OUT}/exact_stiff && test $(wc -l < ${PWL_CLI_OUT}/exact_stiff/poincare.csv) -eq 22 && awk -F, 'NR > 1 { for (i = 2; i <= 6; ++i) if ($i > 3 || $i < -3) bad = 1 } END { exit bad }' ${PWL_CLI_OUT}/exact_stiff/poincare.csv && \"$<TARGET_FILE:pwl>\" simulate --n 5 --alpha 1e9 --method exact --periods 5 --quiet --out ${PWL_CLI_OUT}/exact_stiff5 && \"$<TARGET_FILE:pwl>\" simulate --n 5 --alpha 1e9 --method rkf78 --tol 1e-13 --locate-kinks --periods 5 --quiet --out ${PWL_CLI_OUT}/exact_stiff_rkf78 && ${PWL_COMPARE_POINCARE} ${PWL_CLI_OUT}/exact_stiff5/poincare.csv ${PWL_CLI_OUT}/exact_stiff_rkf78/poincare.csv 6 3e-8")
# Row 4, the undamped resonance called unbounded, is cli_analyze_undamped_resonance_unbounded
# (bad_values.cmake).
# The adaptive rows have no step to judge; their tolerance is. Looser than 1e-5 (where pwl bench
# stability finds them missing contacts or settling on the wrong regime) draws a warning, in a
# single case and once for a whole sweep; 1e-5 and tighter nothing.
add_test(NAME cli_simulate_loose_tolerance_warning
         COMMAND sh -c "\"$<TARGET_FILE:pwl>\" simulate --figure 4a --method dopri5 --tol 1e-3 --periods 2 --quiet --out ${PWL_CLI_OUT}/loose_tolerance 2>&1 && \"$<TARGET_FILE:pwl>\" simulate --figure 4a --method dopri5 --tol 1e-5 --periods 2 --quiet --out ${PWL_CLI_OUT}/tight_tolerance 2>&1")
set_tests_properties(cli_simulate_loose_tolerance_warning PROPERTIES
                     PASS_REGULAR_EXPRESSION "^pwl: warning: dopri5: tolerance 0.001 is loose for gap springs.*use a tolerance of at most 1e-05\n$")
add_test(NAME cli_sweep_loose_tolerance_warning
         COMMAND pwl sweep --figure 4a --parameter theta --range 1:1.2 --points 3 --transient 2
                 --periods 2 --method rkf78 --locate-kinks --tol 1e-4 --no-lyapunov --no-plot
                 --quiet --out ${PWL_CLI_OUT}/loose_tolerance_sweep)
set_tests_properties(cli_sweep_loose_tolerance_warning PROPERTIES PASS_REGULAR_EXPRESSION
                     "pwl: warning: 3 of the 3 points of this study draw a warning from the step guard \\(the same for every point\\); the first, point 0: rkf78: tolerance 0.0001 is loose")
