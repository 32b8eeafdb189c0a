# Installs the pwl build into a scratch prefix, builds apps/library_example against it through
# find_package(pwl), and runs it. Called by ctest with -DBUILD_DIR -DSOURCE_DIR -DWORK_DIR
# -DSANITIZE.
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()
set(flags "")
if(SANITIZE)  # the installed static libraries carry the sanitizers' instrumentation
  set(flags -DCMAKE_CXX_FLAGS=-fsanitize=address,undefined
            -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release ${flags}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the example against the installed pwl failed (${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the example failed (${rc})")
endif()
execute_process(COMMAND ${WORK_DIR}/build/poincare_points RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the example failed (${rc})")
endif()

# The installed program draws with the scripts under its own prefix, not the source tree's: it
# draws a figure, and no longer does once the prefix's scripts are moved away.
set(pwl ${WORK_DIR}/prefix/bin/pwl)
set(scripts ${WORK_DIR}/prefix/share/pwl/scripts)
if(NOT EXISTS ${scripts}/phase_portrait.gp OR NOT EXISTS ${WORK_DIR}/prefix/share/pwl/scenes/paper_fig4a.toml)
  message(FATAL_ERROR "cmake --install put no scripts or scenes under share/pwl")
endif()
foreach(run installed moved)
  if(run STREQUAL "moved")
    file(RENAME ${scripts} ${scripts}_moved)
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=PWL_PLOTS_DIR --unset=PWL_SCENES_DIR
                          ${pwl} simulate --figure 4a --periods 3 --record 5 --quiet
                          --out ${WORK_DIR}/${run}
                  WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the installed pwl failed (${rc}): ${err}")
  endif()
  if(run STREQUAL "installed" AND NOT EXISTS ${WORK_DIR}/installed/phase.png)
    message(FATAL_ERROR "the installed pwl drew no figure: ${err}")
  endif()
  if(run STREQUAL "moved" AND (EXISTS ${WORK_DIR}/moved/phase.png OR NOT err MATCHES "share/pwl/scripts"))
    message(FATAL_ERROR "the installed pwl did not read its scripts from its prefix: ${err}")
  endif()
endforeach()
file(RENAME ${scripts}_moved ${scripts})
message(STATUS "the installed pwl draws with ${scripts}")
