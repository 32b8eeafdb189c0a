# Figures go through a gnuplot-iostream session (apps/pwl/output/gnuplot.cpp). Three cases, run
# with `cmake -DPWL=<pwl> -DWORK_DIR=<dir> -DSOURCE_DIR=<repo> -P figures.cmake`:
#   1. a title holding quotes and gnuplot's own syntax, or a line break, reaches the figure as text;
#   2. without gnuplot on PATH the run still succeeds, writes its CSV, and says why there is no
#      figure;
#   3. a script that gnuplot rejects is reported as a failed figure (gnuplot's exit status is
#      read), not as a figure written, and the run keeps its CSV.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(case simulate --figure 4a --periods 3 --record 5)

function(run_pwl out)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE stdout
                  ERROR_VARIABLE stderr)
  set(${out}_code ${code} PARENT_SCOPE)
  set(${out}_stdout "${stdout}" PARENT_SCOPE)
  set(${out}_stderr "${stderr}" PARENT_SCOPE)
endfunction()

# 1. A title reaches the figure as text and runs nothing: the run `name` with --title `title`
#    exits 0 and writes its figure and CSV, phase.svg holds `shown`, and the file `injected`,
#    which the title would create if gnuplot ran a piece of it, does not exist.
function(check_title name title shown injected)
  run_pwl(run ${PWL} ${case} --title "${title}" --out ${WORK_DIR}/${name})
  if(NOT run_code EQUAL 0)
    message(FATAL_ERROR "${name}: run failed (${run_code}): ${run_stderr}")
  endif()
  foreach(f phase.png phase.svg poincare.csv)
    if(NOT EXISTS ${WORK_DIR}/${name}/${f})
      message(FATAL_ERROR "${name}: no ${f}: ${run_stdout} ${run_stderr}")
    endif()
  endforeach()
  file(READ ${WORK_DIR}/${name}/phase.svg svg)
  string(FIND "${svg}" "${shown}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${name}: \"${shown}\" is not in phase.svg")
  endif()
  if(EXISTS ${injected})
    message(FATAL_ERROR "${name}: a piece of the title was run as a gnuplot command")
  endif()
endfunction()
# Single and double quotes, and a gnuplot expression that would run a command if the title were
# not passed as a string.
check_title(titled "it's \"quoted\" ' . system('touch ${WORK_DIR}/injected') . '" "system("
            ${WORK_DIR}/injected)
# A line break would end gnuplot's command there and run the next line: it becomes a space, and
# the line after it stays text.
check_title(broken_line "first line\nsystem(\"touch ${WORK_DIR}/injected_by_newline\")\r\n"
            "first line system(" ${WORK_DIR}/injected_by_newline)

# 2. No gnuplot on PATH.
file(MAKE_DIRECTORY ${WORK_DIR}/empty_bin)
run_pwl(bare ${CMAKE_COMMAND} -E env PATH=${WORK_DIR}/empty_bin ${PWL} ${case}
        --out ${WORK_DIR}/bare)
if(NOT bare_code EQUAL 0 OR NOT EXISTS ${WORK_DIR}/bare/poincare.csv
   OR EXISTS ${WORK_DIR}/bare/phase.png)
  message(FATAL_ERROR "without gnuplot: exit ${bare_code}, ${bare_stdout} ${bare_stderr}")
endif()
string(FIND "${bare_stderr}" "no figure: gnuplot is not installed" at)
if(at EQUAL -1)
  message(FATAL_ERROR "without gnuplot, no word of it: ${bare_stderr}")
endif()

# 3. A script gnuplot rejects, in a plots folder of its own.
file(MAKE_DIRECTORY ${WORK_DIR}/broken_plots/scripts)
file(WRITE ${WORK_DIR}/broken_plots/scripts/phase_portrait.gp
     "set terminal pngcairo\nset output out\nplot trajectory using xcol:vcol with no_such_style\n")
run_pwl(broken ${CMAKE_COMMAND} -E env PWL_PLOTS_DIR=${WORK_DIR}/broken_plots ${PWL} ${case}
        --out ${WORK_DIR}/broken)
if(NOT broken_code EQUAL 0 OR NOT EXISTS ${WORK_DIR}/broken/poincare.csv)
  message(FATAL_ERROR "broken script: exit ${broken_code}, ${broken_stdout} ${broken_stderr}")
endif()
string(FIND "${broken_stderr}" "no figure: gnuplot failed on ${WORK_DIR}/broken_plots/scripts/phase_portrait.gp" at)
string(FIND "${broken_stdout}" "wrote ${WORK_DIR}/broken/phase.png" claimed)
if(at EQUAL -1 OR NOT claimed EQUAL -1)
  message(FATAL_ERROR "a rejected script was not reported: ${broken_stdout} ${broken_stderr}")
endif()
message(STATUS "figures: titled, without gnuplot and with a rejected script all as expected")
