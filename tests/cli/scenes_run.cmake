cmake_minimum_required(VERSION 3.25)
# Every shipped scene (apps/scenes/*.toml) runs as `pwl run SCENE` at a small size, with its output
# under WORK_DIR, and exits 0: the scenes are the examples of apps/scenes/README.md, and none may
# rot. The small sizes are the table below, one entry per scene (its --set overrides separated by
# spaces; @ is the scene's output folder); a scene without an entry fails
# the test (add one), as does an entry without a scene, and apps/scenes/README.md must list each.
# Variables: PWL (the program), SOURCE_DIR (the source tree), WORK_DIR.
set(small
  "bench_accuracy.toml|run.quick=true output.no_plot=true output.plots=@"
  "bench_chain.toml|structure.masses=100 run.t_end=8 run.runs=1 run.dense_runs=1"
  "bench_orbits.toml|run.quick=true run.quiet=true"
  "bench_curves.toml|run.quick=true"
  "bench_scaling.toml|bench.sizes=[1000,2000] run.steps=50 run.repeats=1 run.work=1e6"
  "bench_stability.toml|run.quick=true output.no_plot=true output.plots=@"
  "bench_sweep.toml|bench.points=8 run.transient=20 run.periods=100 run.repeats=1"
  "chain1000_continuation.toml|structure.masses=250 continuation.max_points=3 continuation.record=1,250 run.transient=50"
  "five_dof_continuation.toml|continuation.range=0.65:0.72 continuation.over_sweep=8 continuation.over_periods=40 run.transient=50"
  "five_dof_orbit.toml|"
  "hardening_basins.toml|basin.x_points=21 basin.y_points=21 run.transient=100 run.periods=40"
  "paper_fig4a.toml|run.periods=300 run.skip_periods=200"
  "paper_fig4b.toml|run.periods=300 run.skip_periods=200"
  "paper_fig5.toml|run.periods=400 analysis.transient=250"
  "paper_fig6.toml|run.periods=400 analysis.transient=250"
  "paper_fig7-9_table1.toml|structure.masses=200 method.reference_tol=1e-10 run.runs=1 run.t_end=20"
  "theta_alpha_curves.toml|continuation.range=0.98:1.02 continuation.curves=alpha=4.5:5.5 run.transient=50 output.no_plot=true"
  "theta_alpha_map.toml|map.x_points=5 map.y_points=4 run.transient=50 run.periods=100 run.quick=true"
  "theta_sweep.toml|sweep.points=12 run.transient=50 run.periods=100 run.quick=true"
  "two_mass_stop.toml|"
  "two_mass_stop_gap_sweep.toml|sweep.points=6 run.transient=50 run.periods=60")
file(GLOB scenes RELATIVE ${SOURCE_DIR}/apps/scenes ${SOURCE_DIR}/apps/scenes/*.toml)
file(READ ${SOURCE_DIR}/apps/scenes/README.md index)
set(known "")
foreach(entry ${small})
  string(REGEX REPLACE "[|].*$" "" name "${entry}")
  list(APPEND known ${name})
  if(NOT name IN_LIST scenes)
    message(FATAL_ERROR "tests/cli/scenes_run.cmake has sizes for ${name}, which apps/scenes lacks")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
set(ran 0)
foreach(scene ${scenes})
  if(NOT scene IN_LIST known)
    message(FATAL_ERROR "apps/scenes/${scene} has no small sizes in tests/cli/scenes_run.cmake: add them")
  endif()
  string(FIND "${index}" "${scene}" listed)
  if(listed EQUAL -1)
    message(FATAL_ERROR "apps/scenes/README.md does not list ${scene}")
  endif()
  string(REGEX REPLACE "[.]toml$" "" stem "${scene}")
  set(out ${WORK_DIR}/${stem})
  file(MAKE_DIRECTORY ${out})
  set(arguments run ${SOURCE_DIR}/apps/scenes/${scene} --set output.out=${out})
  foreach(entry ${small})
    if(entry MATCHES "^${scene}[|](.*)$")
      string(REPLACE "@" "${out}" settings "${CMAKE_MATCH_1}")
      separate_arguments(settings UNIX_COMMAND "${settings}")
      foreach(setting ${settings})
        list(APPEND arguments --set ${setting})
      endforeach()
    endif()
  endforeach()
  execute_process(COMMAND ${PWL} ${arguments} WORKING_DIRECTORY ${out}
                  RESULT_VARIABLE status OUTPUT_VARIABLE printed ERROR_VARIABLE errors)
  if(NOT status EQUAL 0)
    list(JOIN arguments " " command)
    message(FATAL_ERROR "pwl ${command} failed (${status}):\n${printed}\n${errors}")
  endif()
  math(EXPR ran "${ran} + 1")
endforeach()
message(STATUS "every shipped scene ran at a small size: ${ran} scenes")
