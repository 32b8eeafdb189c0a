# `pwl reproduce --quick` writes only under <plots>/data/quick: the figures, the data and the report
# of a full run in the same plots folder stay as they were. Variables: PWL, WORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
set(full_files figures/fig4a.png figures/bifurcation_theta.png data/paper_fig4a/poincare.csv
               data/theta_sweep/classification.csv report.md)
foreach(f ${full_files})
  file(WRITE ${WORK_DIR}/plots/${f} "a full run's ${f}\n")
endforeach()
execute_process(COMMAND ${PWL} reproduce --quick --only 4a,theta-sweep --plots ${WORK_DIR}/plots
                RESULT_VARIABLE status OUTPUT_VARIABLE printed ERROR_VARIABLE errors)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "pwl reproduce --quick failed (${status}):\n${printed}\n${errors}")
endif()
foreach(f ${full_files})
  file(READ ${WORK_DIR}/plots/${f} content)
  if(NOT content STREQUAL "a full run's ${f}\n")
    message(FATAL_ERROR "pwl reproduce --quick overwrote ${f} of the full run")
  endif()
endforeach()
foreach(f figures/fig4a.png figures/bifurcation_theta.png paper_fig4a/poincare.csv
          theta_sweep/classification.csv report_quick.md)
  if(NOT EXISTS ${WORK_DIR}/plots/data/quick/${f})
    message(FATAL_ERROR "pwl reproduce --quick did not write data/quick/${f}")
  endif()
endforeach()
list(LENGTH full_files kept)
message(STATUS "reproduce --quick kept the full run's ${kept} files and wrote its own under data/quick")
